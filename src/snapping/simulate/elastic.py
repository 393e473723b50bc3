"""The extensible, tension-only line: the public names in one place.

* :mod:`~snapping.simulate.elastic_model`: what the line is made of (:class:`Elastic`) and the
  line itself (:class:`ElasticLine`: the problem's links as springs, the starts, the statics);
* :mod:`~snapping.simulate.elastic_statics`: the static equilibrium (the stretched start);
* :mod:`~snapping.simulate.elastic_kernels`: the compiled forces, banded Jacobian, measures;
* :mod:`~snapping.simulate.elastic_solve`: the stepping (:func:`solve`) and the run Dataset;
* :mod:`~snapping.simulate.elastic_rodas`: the compiled RODAS4 (``method="rodas4"``);
* :mod:`~snapping.simulate.elastic_loads`: snap loads in SI (:func:`climbing_fall`, :func:`jerk_taut`: a
  slack tether jerked taut by its moving end, beside :func:`jerk_peak_force`).

Example
-------
>>> from snapping.simulate.problem import Links, Problem
>>> from snapping.simulate.elastic import Elastic, solve
>>> r = solve(Problem.catenary(0.25, links=Links.uniform(8, lumping="shared")), Elastic(ea=400.0), t_end=0.05,
...           tol=1e-6)
>>> r.dataset.attrs["status"]
'completed'
"""

from .elastic_loads import EN892_LIMIT, climbing_fall, jerk_peak_force, jerk_taut, massless_peak_force
from .elastic_model import STARTS, Elastic, ElasticLine
from .elastic_solve import METHODS, ElasticRun, solve

__all__ = ["Elastic", "ElasticLine", "ElasticRun", "solve", "STARTS", "METHODS", "climbing_fall", "massless_peak_force",
           "EN892_LIMIT", "jerk_peak_force", "jerk_taut"]
