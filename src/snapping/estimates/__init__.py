"""Design-rule estimates of the snap from the initial geometry alone.

The initial shape is the paper's catenary of unit length hanging from the pin at
the origin with its free end at (chi, 0) (gravity along +e2, so ``y`` grows
downward). From it follow the initial maximum curvature kappa_m(0) = 1/a, the
available energy P (catenary minus the vertically hanging string), the
regularising length scales delta and, through the rigid whirling-rod model of
the paper's eq. (estimates), predictions of the peak speed, acceleration and
tension. :class:`Chain` carries these to SI units.

Nondimensional units: length l, velocity sqrt(g l), acceleration g, force
rho g l = M g, time sqrt(l/g).

Example
-------
>>> import math
>>> from snapping import estimates
>>> a = estimates.catenary_parameter(0.25)
>>> round(a, 6), round(2 * a * math.sinh(0.25 / (2 * a)), 12)   # 1 = 2 a sinh(chi/2a)
(0.038299, 1.0)
>>> est = estimates.design_estimate(estimates.Chain(), chi=0.25)   # the paper's chain
>>> round(est.nondim["kappa_m0"], 2), round(est.si["kappa_m0_per_m"], 2)   # 1/l and 1/m
(26.11, 25.55)
>>> {k: round(v) for k, v in est.predictions["delta_c"].items()}
{'v': 7, 'a': 1728, 'sigma': 26}
"""

from .catenary import *  # noqa: F401,F403
from .catenary import _A_MAX, _A_MIN, _log_sinhc  # noqa: F401
from .catenary import __all__ as _catenary_all
from .rules import *  # noqa: F401,F403
from .rules import _t_star  # noqa: F401
from .rules import __all__ as _rules_all

__all__ = [*_catenary_all, *_rules_all]
