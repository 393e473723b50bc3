"""The elastic line's "matched" start (snapping.simulate.elastic_statics.matched): the start's
shape stretched to the rigid chain's tensions after release, so that no release wave is
launched. Checked against plain-numpy kinematics and an independent dense solve of the rigid
chain's tension system (written here from the node equations, not from the project's rows)."""

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import general as G
from snapping.simulate.elastic import Elastic, ElasticLine, solve
from snapping.simulate.pin import PinMotion
from snapping.simulate.problem import Links, Problem


def _catenary(N=16, c=10.0):
    return ElasticLine(Problem.catenary(0.25, links=Links.uniform(N, lumping="shared")), Elastic.from_wave_speed(c))


def _coarse(N=10, c=10.0):
    """A coarse catenary: the rigid chain would compress its free arm after release (slack links)."""
    return _catenary(N, c)


def _spun_pulled(N=12, c=10.0):
    """A catenary turning rigidly about its held end (omega = 0.7) with a tip mass, its held end
    pulled (accelerating at t = 0): velocities and the held end's acceleration both enter."""
    cat = Problem.catenary(0.3, links=Links.uniform(N, tip_mass=0.2, lumping="shared"))
    om = 0.7
    vx, vy = -om * cat.y, om * cat.x  # omega x (r - r_pin), the held end at the origin
    pr = Problem.nodes(cat.x, cat.y, links=cat.links, vx=vx, vy=vy, pin=PinMotion.pull((0.4, -0.9)))
    return ElasticLine(pr, Elastic.from_wave_speed(c))


def _nodes(line, z):
    x, y, vx, vy = line.unpack(z, 0.0)
    dz = line.rhs(0.0, z)
    pa = line.pin.kinematics(0.0)
    ax = np.append(dz[2:4 * line.N:4], pa[4])
    ay = np.append(dz[3:4 * line.N:4], pa[5])
    return x, y, vx, vy, ax, ay


def _dense_tensions(x, y, vx, vy, m, g, A):
    """The rigid chain's tensions on the geometry (x, y), velocities (vx, vy): the links' length
    kept, l_j'' = (a_{j+1} - a_j).u_j + |w_j|^2/l_j = 0 with a_i = (T_i u_i - T_{i-1} u_{i-1})/m_i
    + g e_y, a_N = A; assembled column by column (unit tensions), solved densely."""
    N = len(m)
    dx, dy = np.diff(x), np.diff(y)
    ln = np.hypot(dx, dy)
    u = np.stack([dx / ln, dy / ln], 1)
    dv = np.stack([np.diff(vx), np.diff(vy)], 1)
    w2 = (dv ** 2).sum(1) - ((dv * u).sum(1)) ** 2

    def l2(T, grav, A):
        a = np.zeros((N + 1, 2))
        for i in range(N):
            F = T[i] * u[i] - (T[i - 1] * u[i - 1] if i > 0 else 0.0)
            a[i] = F / m[i] + grav * np.array([0.0, g])
        a[N] = A
        return ((a[1:] - a[:-1]) * u).sum(1)

    M = np.column_stack([l2(np.eye(N)[k], 0.0, np.zeros(2)) for k in range(N)])
    b = l2(np.zeros(N), 1.0, np.asarray(A)) + w2 / ln
    return np.linalg.solve(M, -b)


@pytest.mark.parametrize("make", [_catenary, _spun_pulled, _coarse])
def test_matched_links_do_not_accelerate_their_length(make):
    """(a) every taut link's d2l/dt2 at t = 0, from the rhs's node accelerations in plain numpy,
    is zero to round-off (the stretched start's is O(1): its release launches the wave); a
    slack one's (the coarse chain's free arm, which the rigid chain would compress) is <= 0."""
    line = make()
    z = line.start("matched")
    x, y, vx, vy, ax, ay = _nodes(line, z)
    dx, dy, dvx, dvy = np.diff(x), np.diff(y), np.diff(vx), np.diff(vy)
    ln = np.hypot(dx, dy)
    ldot = (dx * dvx + dy * dvy) / ln
    l2 = (np.diff(ax) * dx + np.diff(ay) * dy) / ln + (dvx ** 2 + dvy ** 2 - ldot ** 2) / ln
    scale = float(np.hypot(ax, ay).max())
    assert np.abs(ldot).max() < 1e-13 * max(1.0, float(np.hypot(vx, vy).max()))
    T, _, _ = line.link_state(0.0, z)
    taut = T > 1e-12 * float(T.max())
    assert taut.sum() >= line.N // 2
    # taut: l'' = 0; slack (the rigid chain would push): l'' <= 0, the link does not pull taut again
    assert np.abs(l2[taut]).max() < 1e-10 * scale
    assert (make is _coarse) == (not taut.all())
    assert np.all(l2[~taut] < 1e-10 * scale)
    if line.pin.kind == "fixed" and np.all(line.problem.vx == 0.0):  # the stretched start's is not zero
        zs = line.start("stretched")
        x, y, vx, vy, ax, ay = _nodes(line, zs)
        dx, dy = np.diff(x), np.diff(y)
        assert np.abs((np.diff(ax) * dx + np.diff(ay) * dy) / np.hypot(dx, dy)).max() > 0.1 * scale


@pytest.mark.parametrize("make", [_catenary, _spun_pulled])
def test_matched_accelerations_are_the_rigid_chains(make):
    """(b) the node accelerations equal the rigid chain's on the same (stretched) geometry, from
    the project's dense reference of the link-angle rows."""
    line = make()
    z = line.start("matched")
    x, y, vx, vy, ax, ay = _nodes(line, z)
    dx, dy = np.diff(x), np.diff(y)
    ln = np.hypot(dx, dy)
    th = np.arctan2(dy, dx)
    om = (-np.sin(th) * np.diff(vx) + np.cos(th) * np.diff(vy)) / ln
    mdl = G.make_model(ln, 1.0 / line.m, g=line.g, **line.pin.model_args())
    t0 = float(np.nextafter(0.0, 1.0))  # (a pull from t = 0: its acceleration from then on)
    f = G.dense_reference_rhs(t0, np.concatenate([th, om, [0.0]]), mdl)
    al = f[line.N:2 * line.N]
    # d_j'' = l_j (theta_j'' n_j - theta_j'^2 t_j); a_j = a_{j+1} - d_j''
    ddx = ln * (-al * np.sin(th) - om ** 2 * np.cos(th))
    ddy = ln * (al * np.cos(th) - om ** 2 * np.sin(th))
    pa = line.pin.kinematics(0.0)
    rx = pa[4] - np.concatenate([np.cumsum(ddx[::-1])[::-1], [0.0]])
    ry = pa[5] - np.concatenate([np.cumsum(ddy[::-1])[::-1], [0.0]])
    scale = float(np.hypot(ax, ay).max())
    assert np.abs(ax - rx).max() < 1e-10 * scale and np.abs(ay - ry).max() < 1e-10 * scale


@pytest.mark.parametrize("make", [_catenary, _spun_pulled, _coarse])
def test_matched_strains_are_the_rigid_tensions_over_ea(make):
    """(c) each link's strain is T/EA with T from an independent dense solve of the rigid
    chain's tension system, and the links keep the start's directions."""
    line = make()
    z = line.start("matched")
    x, y, vx, vy, _, _ = _nodes(line, z)
    pa = line.pin.kinematics(0.0)
    T = _dense_tensions(x, y, vx, vy, line.m, line.g, pa[4:6])
    _, e, _ = line.link_state(0.0, z)
    k = 0  # (the rigid chain compresses links up to k - 1: they and the piece they join fall slack)
    if T.min() <= 0.0:
        k = int(np.flatnonzero(T <= 0.0)[-1]) + 1
        assert make is _coarse and 0 < k < line.N
        T = np.concatenate([np.zeros(k), _dense_tensions(x[k:], y[k:], vx[k:], vy[k:], line.m[k:], line.g, pa[4:6])])
    assert T[k:].min() > 0.0
    assert np.allclose(e, T / line.ea, rtol=1e-9, atol=1e-15)
    p = line.problem
    th0 = np.arctan2(np.diff(p.y), np.diff(p.x))
    assert np.abs(np.arctan2(np.diff(y), np.diff(x)) - th0).max() < 1e-13
    assert np.abs(np.hypot(np.diff(x), np.diff(y)) - line.h * (1 + T / line.ea)).max() < 1e-14
    # the start's angular velocities kept (the held end's velocity too): the links turn as the problem's
    om0 = (-np.sin(th0) * np.diff(p.vx) + np.cos(th0) * np.diff(p.vy)) / line.h
    th = np.arctan2(np.diff(y), np.diff(x))
    om = (-np.sin(th) * np.diff(vx) + np.cos(th) * np.diff(vy)) / np.hypot(np.diff(x), np.diff(y))
    assert np.abs(om - om0).max() < 1e-12 * max(1.0, float(np.abs(om0).max()))
    assert (vx[-1], vy[-1]) == tuple(line.pin.kinematics(0.0)[2:4])
    if make is _spun_pulled:
        assert np.abs(om0 - 0.7).max() < 1e-12


def test_matched_table_inverts_the_curve():
    """A tension-strain table: the strain is the curve's inverse at the rigid tension (linear
    interpolation between the table's points, checked by hand)."""
    pr = Problem.catenary(0.25, links=Links.uniform(16, lumping="shared"))
    tab = ([0.0, 1e-3, 5e-3], [0.0, 0.05, 2.0])
    line = ElasticLine(pr, Elastic(table=tab))
    z = line.start("matched")
    x, y, vx, vy, _, _ = _nodes(line, z)
    T = _dense_tensions(x, y, vx, vy, line.m, line.g, (0.0, 0.0))
    want = np.where(T <= 0.05, T / 0.05 * 1e-3, 1e-3 + (T - 0.05) / 1.95 * 4e-3)
    assert T.min() > 0.0 and T.max() > 0.1  # (both segments used)
    assert np.allclose(line.link_state(0.0, z)[1], want, rtol=1e-9, atol=1e-15)


def test_matched_start_recorded_and_bad_start_named():
    """(d) the run's Dataset records the start; an unknown start name is refused, named."""
    pr = Problem.catenary(0.25, links=Links.uniform(6, lumping="shared"))
    r = solve(pr, Elastic.from_wave_speed(10.0), t_end=0.02, tol=1e-5, method="rodas4", start="matched")
    assert r.dataset.attrs["start"] == "matched" and r.dataset.attrs["status"] == "completed"
    with pytest.raises(SnappingInputError, match="start='matchd'"):
        solve(pr, Elastic.from_wave_speed(10.0), t_end=0.02, start="matchd")
    with pytest.raises(SnappingInputError, match="start='rigid'"):
        ElasticLine(pr, Elastic.from_wave_speed(10.0)).start("rigid")


def test_cli_elastic_start(tmp_path, capsys):
    """`snapping simulate --stretching C --elastic-start matched`: the run file records the start
    and its strains are the matched start's; --elastic-start without the extensible line, or an
    unknown start, is one line, exit 2, before any work."""
    import xarray as xr

    from snapping.cli import main

    base = ["simulate", "--chi", "0.25", "--N", "6", "--t-end", "0.01", "--no-progress"]
    out = tmp_path / "m.nc"
    assert main(base + ["--stretching", "10", "--elastic-start", "matched", "-o", str(out)]) == 0
    with xr.open_dataset(out) as ds:
        assert ds.attrs["start"] == "matched"
        e0 = ds.strain.values[0]
    line = ElasticLine(Problem.catenary(0.25, links=Links.uniform(6, lumping="shared")), Elastic.from_wave_speed(10.0))
    assert np.allclose(e0, line.link_state(0.0, line.start("matched"))[1], rtol=1e-12, atol=1e-15)
    capsys.readouterr()
    assert main(base + ["--elastic-start", "matched", "-o", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--elastic-start matched is the extensible line's start" in err, err
    assert not (tmp_path / "x.nc").exists()
    with pytest.raises(SystemExit) as exc:
        main(base + ["--stretching", "10", "--elastic-start", "rigid"])
    assert exc.value.code == 2 and "rigid" in capsys.readouterr().err


def test_converge_and_sweep_check_the_elastic_start():
    """converge(elastic_start=...) and a sweep's start are checked before any run, named."""
    from snapping import continuum
    from snapping.sweep_elastic import solve_kwargs

    el = Elastic.from_wave_speed(10.0)
    with pytest.raises(SnappingInputError, match="elastic_start='tight'"):
        continuum.converge(0.25, elastic=el, elastic_start="tight", n0=4, levels=3)
    with pytest.raises(SnappingInputError, match="elastic_start='matched' is the extensible line's start"):
        continuum.converge(0.25, elastic_start="matched", levels=3)
    assert solve_kwargs({"chi": 0.25, "N": 4, "elastic": el, "start": "matched"})["start"] == "matched"
    with pytest.raises(SnappingInputError, match="start='tight'"):
        solve_kwargs({"chi": 0.25, "N": 4, "elastic": el, "start": "tight"})
