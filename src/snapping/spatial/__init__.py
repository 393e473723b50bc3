"""The chain in three dimensions (rigid links, directions in space, O(N) tension solve).

* :mod:`snapping.spatial.chain3d`: the equations (tridiagonal tension system with the
  cosines between neighbouring links), the compiled right-hand side and diagnostics;
* :mod:`snapping.spatial.solve3d`: compiled DOP853 stepping with dense-output peaks, to the snap;
  :mod:`snapping.spatial.error3d`: its steps' error norm (the links' angle and rate errors);
* :mod:`snapping.spatial.starts3d`: :class:`Problem3D`, planar starts in space and the
  out-of-plane perturbations only 3D has, the whirling start (steady or spun up), any curve;
* :mod:`snapping.spatial.held3d`: :class:`Pin3D`, the held end's motion in space (pull,
  flick, a circle, sampled points of any curve); :mod:`snapping.spatial.motion3d`: its
  compiled form (``r_p(t)`` in the kernels);
* :mod:`snapping.spatial.shape3d`: start curves in space (files of x, y, z; exact chords;
  a start that crosses itself refused);
* :mod:`snapping.spatial.dataset3d`: the run Dataset of a 3D run (the planar names, and
  ``z``, ``vz``, ``z_amp``, ... of ``snapping.schema.SPATIAL_VARS``);
* :mod:`snapping.spatial.figures3d`: the out-of-plane amplitude against eps, the chain in space.
* :mod:`snapping.spatial.stability`: does the planar snap stay planar? The out-of-plane
  amplification at the snap against N, extrapolated, and a computed verdict.
* :mod:`snapping.spatial.forces3d`: a line's body in space (bending, damping, drag, a 3D
  wind) as node forces; :mod:`snapping.spatial.stiffness3d`: how stiff bending makes a 3D run.

It imports from :mod:`snapping.simulate` (links, the catenary, the DOP853 tableau); the
planar simulator does not import it.
"""

from .solve3d import run3d
from .held3d import Pin3D
from .starts3d import Problem3D

__all__ = ["run3d", "Problem3D", "Pin3D"]
