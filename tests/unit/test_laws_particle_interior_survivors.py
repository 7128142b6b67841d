"""Law tests for the mutation survivors of :mod:`drumflow.physics.particle_interior` (issue 36;
results/mutation/survivors.md).

The mutmut run (tree of d6ddc82, where the module was ``drumflow/coolers/particle_interior.py``)
left alive: the Biot number at which :func:`shell_drop_error` measures (its unit sphere's
diameter: the tests compared the error only with itself); the surface temperature of
:class:`ShellBatch` and of :class:`SphereConduction` (area, film drop, the insulated and
h = inf branches: the tests only asked for a value between the outer shell and the air);
film coefficients in (0, 1] W/(m^2 K) treated as insulated; the h = inf surface conductance;
the shell centres; the sub-step rule of :meth:`ShellBatch.sub_steps` (no test had a hand
value); :meth:`SphereConduction.advance` at zero duration and at exactly 1 s; the order of
the eigenvalues; the argument guards and their messages; warnings of insulated rows. Each
expected value below is independent of the module:

* the exact series solution of a sphere at Bi = 1 (Carslaw and Jaeger 1959, sec. 9.4): the
  roots of 1 - z cot z = 1 are z_n = (2n - 1) pi / 2 exactly, so the mean excess is
  theta(Fo) = (96 / pi^4) sum_n exp(-(2n - 1)^2 pi^2 Fo / 4) / (2n - 1)^4 (theta(0) = 1:
  sum 1 / (2n - 1)^4 = pi^4 / 96);
* the finite-volume shells written out here as a dense matrix (volumes 4/3 pi (r_o^3 - r_i^3),
  face conductance k 4 pi r^2 / dr, surface 1 / (1 / (h A) + (dr / 2) / (k A))), advanced
  exactly with a matrix exponential or one Crank-Nicolson step solved with
  :func:`numpy.linalg.solve` (not the Thomas sweep under test);
* closed forms: the film share of the outer half-shell and film, the sub-step count.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.linalg import expm

from drumflow.physics import particle_interior as pi_mod
from drumflow.physics.particle_interior import ShellBatch

K_NPK = 0.18596  # W/(m K), NPK (test_shell_batch)
RHO_C = 1050.0 * 1465.38  # J/(m3 K)
ALPHA = K_NPK / RHO_C  # 0.18596 / 1538649 = 1.208593e-7 m2/s


def _close(value: float, reference: float, rtol: float, what: str) -> None:
    assert math.isfinite(value) and abs(value / reference - 1.0) <= rtol, (
        f"{what}: {value:.10g} vs independent {reference:.10g} "
        f"({value / reference - 1.0:+.3%}, allowed {rtol:.1e})")


def _theta_bi1(fo: float, terms: int = 60) -> float:
    """Mean excess of a sphere at Bi = 1 (z_n = (2n - 1) pi / 2), Carslaw and Jaeger."""
    return 96.0 / math.pi**4 * sum(math.exp(-((2 * n - 1) ** 2) * math.pi**2 * fo / 4.0)
                                   / (2 * n - 1) ** 4 for n in range(1, terms + 1))


def _dense_shells(radius: float, shells: int, k: float, rho_c: float, h: float,
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Volumes, capacities, conduction matrix K (W/K) and surface conductance of the
    equal-thickness shell model, written out from the module docstring."""
    r = np.linspace(0.0, radius, shells + 1)
    dr = radius / shells
    volumes = 4.0 / 3.0 * math.pi * (r[1:] ** 3 - r[:-1] ** 3)
    area = 4.0 * math.pi * radius**2
    if h == 0.0:
        g_s = 0.0
    elif math.isinf(h):  # the surface at the gas temperature: the outer half-shell alone
        g_s = k * area / (0.5 * dr)
    else:
        g_s = 1.0 / (1.0 / (h * area) + 0.5 * dr / (k * area))
    mat = np.zeros((shells, shells))
    for i in range(shells - 1):
        g = k * 4.0 * math.pi * r[i + 1] ** 2 / dr
        mat[i, i] -= g
        mat[i + 1, i + 1] -= g
        mat[i, i + 1] += g
        mat[i + 1, i] += g
    mat[-1, -1] -= g_s
    return volumes, rho_c * volumes, mat, g_s


@pytest.mark.parametrize(("shells", "reference"), [(5, 6.33326e-3), (10, 1.59087e-3)])
def test_shell_drop_error_at_its_biot_number(shells: int, reference: float) -> None:
    """shell_drop_error(1, n) against the exact sphere and the exactly integrated shells.

    The series time of 63.2 % of the drop: theta(Fo) = e^-1; with the first term alone
    Fo = (4 / pi^2) (1 + ln(96 / pi^4)) = 0.405285 * 1.014678 = 0.399379; with 60 terms
    (bisection here) 0.3993811. The shells (unit sphere, k = rho c = 1, h = Bi = 1), advanced
    to it with expm(C^-1 K Fo): mean excess 0.3718828 (5 shells), 0.3688851 (10), so the
    error of the drop |(1 - mean) / (1 - e^-1) - 1| = 6.33326e-3 and 1.59087e-3 (re-computed
    below). The module's Crank-Nicolson steps of Fo / 200 add 2e-4 and 7e-4 of it: 2 %
    allowed. Measuring at Bi = 1.5 instead (a unit sphere of diameter 3) gives +37 %.
    """
    lo, hi = 1e-6, 5.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _theta_bi1(mid) > math.exp(-1.0) else (lo, mid)
    fo = 0.5 * (lo + hi)
    _close(fo, 0.3993811, 1e-6, "Fo of 63.2 % of the drop at Bi = 1")
    volumes, capacities, mat, _ = _dense_shells(1.0, shells, 1.0, 1.0, 1.0)
    mean = float(volumes @ (expm(mat / capacities[:, None] * fo) @ np.ones(shells)) / volumes.sum())
    exact_error = abs((1.0 - mean) / (1.0 - math.exp(-1.0)) - 1.0)
    _close(exact_error, reference, 1e-5, "shell error by matrix exponential (typed value)")
    _close(pi_mod.shell_drop_error(1.0, shells), exact_error, 2e-2,
           f"shell_drop_error(Bi = 1, {shells} shells)")


def test_batch_step_is_the_dense_crank_nicolson_solve() -> None:
    """One step of three different particles, one insulated, one at h = 0.5 W/(m^2 K),
    one at 80, against (C - dt/2 K) T1 = (C + dt/2 K) T0 + dt g_s T_g e_N solved densely;
    the heat to the gas dt/2 g_s ((T0_N - T_g) + (T1_N - T_g)). Same arithmetic, another
    solver: 1e-12. A film below 1 W/(m^2 K) taken as insulated moves the h = 0.5 row's
    outer shell by 1e-4 of its excess."""
    shells, dt = 6, 0.4
    radius = np.array([1.5e-3, 4e-3, 2.5e-3])
    h = np.array([0.0, 0.5, 80.0])
    gas = np.array([20.0, 35.0, 30.0])
    capacity = RHO_C * 4.0 / 3.0 * math.pi * radius**3
    start = np.array([np.linspace(90.0, 80.0, shells), np.linspace(60.0, 75.0, shells),
                      np.linspace(95.0, 70.0, shells)])
    batch = ShellBatch(shells, K_NPK, ALPHA)
    rows, heat = batch.step(start, h, gas, radius, capacity, dt)
    for i in range(3):
        _, c, mat, g_s = _dense_shells(float(radius[i]), shells, K_NPK, RHO_C, float(h[i]))
        rhs = (np.diag(c) + 0.5 * dt * mat) @ start[i]
        rhs[-1] += dt * g_s * gas[i]
        expected = np.linalg.solve(np.diag(c) - 0.5 * dt * mat, rhs)
        np.testing.assert_allclose(rows[i], expected, rtol=1e-12, err_msg=f"row {i}")
        q = 0.5 * dt * g_s * ((start[i, -1] - gas[i]) + (expected[-1] - gas[i]))
        assert heat[i] == pytest.approx(q, rel=1e-11, abs=1e-300)
    area = 4.0 * math.pi * radius[1] ** 2
    _close(float(batch.surface_conductance(h, radius)[1]),
           1.0 / (1.0 / (0.5 * area) + 0.5 * radius[1] / shells / (K_NPK * area)), 1e-12,
           "surface conductance at h = 0.5")


def test_batch_surface_temperature_closed_form() -> None:
    """Outer shell -> half-shell -> film -> gas in series: the surface sits at
    T_s = T_g + (T_N - T_g) / (1 + h dr / (2 k)), dr = R / N (the film's share of the
    resistance); insulated (h = 0): T_N. With N = 5, k = 0.18596:
    R = 20 mm, h = 0.5: h dr / 2k = 0.5 * 0.004 / 0.37192 = 0.0053775, T_s = 35 + 40 / 1.0053775;
    R = 4 mm, h = 40: 40 * 8e-4 / 0.37192 = 0.086040; R = 1.25 mm, h = 300: 0.201656.
    Closed form both ways: 1e-12."""
    shells = 5
    batch = ShellBatch(shells, K_NPK, ALPHA)
    radius = np.array([1.5e-3, 0.02, 4e-3, 1.25e-3])
    h = np.array([0.0, 0.5, 40.0, 300.0])
    gas = np.array([20.0, 35.0, 30.0, 25.0])
    rows = np.array([np.linspace(80.0, 60.0, shells), np.linspace(90.0, 75.0, shells),
                     np.linspace(70.0, 50.0, shells), np.linspace(60.0, 45.0, shells)])
    surface = batch.surface_temperature(rows, h, radius, gas)
    assert surface[0] == 60.0
    for i in range(1, 4):
        share = h[i] * radius[i] / shells / (2.0 * K_NPK)
        expected = gas[i] + (rows[i, -1] - gas[i]) / (1.0 + share)
        _close(float(surface[i]), float(expected), 1e-12, f"surface temperature, h = {h[i]:g}")
    _close(0.5 * 0.02 / 5 / (2.0 * K_NPK), 0.0053775, 1e-4, "typed film share")


@pytest.mark.parametrize(("shells", "diffusivity", "radius", "duration", "steps"), [
    (4, 0.0625, (0.5, 0.7), 0.25, 4),  # limit 0.25 * 0.125^2 / 0.0625 = 0.0625 s: 4.0 exactly
    (4, 0.0625, (0.5, 0.7), 0.26, 5),  # 4.16 -> 5
    (4, 0.0625, (0.5, 0.7), 0.01, 1),  # shorter than one limit: one step
    (12, ALPHA, (4e-3, 1.35e-3), 0.5, 20),  # 0.25 (1.35e-3 / 12)^2 / 1.208593e-7 = 0.026180 s
])
def test_sub_steps_written_out(shells: int, diffusivity: float, radius: tuple[float, ...],
                               duration: float, steps: int) -> None:
    """ceil(duration / limit), limit a quarter of the thinnest shell's diffusion time
    (min R / N)^2 / alpha, at least one (the SphereConduction default step)."""
    batch = ShellBatch(shells, 0.2, diffusivity)
    assert batch.sub_steps(duration, np.array(radius)) == steps


def test_guards_accept_their_ends_and_name_the_argument() -> None:
    """Two shells are allowed; zero, negative and infinite conductivity or diffusivity are
    refused with the argument's name; a zero duration is refused; shell_drop_error refuses
    Bi = 0, -1 and inf with its own message, sphere_eigenvalues Bi = 0."""
    two = ShellBatch(2, K_NPK, ALPHA)
    assert two.shells == 2
    np.testing.assert_allclose(two.fractions, [0.125, 0.875], rtol=1e-15)
    with pytest.raises(ValueError, match="shells = 1: must be >= 2"):
        ShellBatch(1, K_NPK, ALPHA)
    for bad in (0.0, -1.0, math.inf):
        with pytest.raises(ValueError, match=r"^conductivity = .*finite number > 0"):
            ShellBatch(3, bad, ALPHA)
        with pytest.raises(ValueError, match=r"^diffusivity = .*finite number > 0"):
            ShellBatch(3, K_NPK, bad)
    rows = np.full((1, 3), 50.0)
    one = np.ones(1)
    with pytest.raises(ValueError, match="duration = 0.0: must be > 0"):
        ShellBatch(3, K_NPK, ALPHA).advance(rows, one * 10.0, 20.0, one * 1e-3, one, 0.0)
    for bad in (0.0, -1.0, math.inf):
        with pytest.raises(ValueError, match=r"^biot = .*: must be a finite number > 0"):
            pi_mod.shell_drop_error(bad, 5)
    with pytest.raises(ValueError, match=r"^biot = 0.0: must be > 0"):
        pi_mod.sphere_eigenvalues(0.0, 3)


def test_insulated_rows_raise_no_warning() -> None:
    """h = 0 rows (particles between contacts) are routine in the coupling loop: the
    conductance, the surface temperature and a step of a batch with one give no
    RuntimeWarning (the divisions by h = 0 are masked)."""
    batch = ShellBatch(4, K_NPK, ALPHA)
    h, radius = np.array([0.0, 50.0]), np.array([2e-3, 3e-3])
    rows = np.array([np.linspace(80.0, 60.0, 4), np.linspace(70.0, 50.0, 4)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = batch.surface_conductance(h, radius)
        surface = batch.surface_temperature(rows, h, radius, 30.0)
        batch.step(rows, h, 30.0, radius, np.ones(2), 0.01)
    assert g[0] == 0.0 and surface[0] == 60.0


# -- the one-particle solver and the references ---------------------------------------------
NPK = pi_mod.Sphere(diameter=0.0027, conductivity=K_NPK, density=1050.0, heat_capacity=1465.38)


def test_sphere_properties_written_out() -> None:
    """d = 2.7 mm: V = pi d^3 / 6 = 1.0305995e-8 m3, A = pi d^2 = 2.2902210e-5 m2,
    m = 1050 V = 1.0821294e-5 kg, alpha = 1.208593e-7 m2/s, Bi(50) = 50 * 1.35e-3 / 0.18596
    = 0.3629813 (on the radius). The shell grid: 20 shells by default (the documented count),
    2 allowed; shell centres at (i + 1/2) R / N (fluid_bed reports them as the profile's
    radii), 3 shells of R = 1.35 mm: 0.225, 0.675, 1.125 mm; faces 0.45, 0.9, 1.35 mm."""
    assert pi_mod.SphereConduction(NPK).shells == 20
    assert pi_mod.SphereConduction(NPK, 2).shells == 2
    grid = pi_mod.SphereConduction(NPK, 3)
    np.testing.assert_allclose(grid.r_centres, [0.225e-3, 0.675e-3, 1.125e-3], rtol=1e-12)
    np.testing.assert_allclose(grid.r_faces, [0.45e-3, 0.9e-3, 1.35e-3], rtol=1e-12)
    _close(NPK.volume, 1.0305995e-8, 1e-7, "volume")
    _close(NPK.surface, 2.2902210e-5, 1e-7, "surface")
    _close(NPK.mass, 1.0821294e-5, 1e-7, "mass")
    _close(NPK.diffusivity, 1.208593e-7, 1e-6, "diffusivity")
    _close(NPK.biot(50.0), 0.3629813, 1e-7, "Biot number h R / k")


@pytest.mark.parametrize("h", [0.0, 0.5, 80.0, math.inf])
def test_sphere_step_is_the_dense_crank_nicolson_solve(h: float) -> None:
    """SphereConduction.step against the dense solve of the shells written out (as for the
    batch); h = inf is the outer half-shell alone, g_s = k A / (dr / 2). The heat is
    dt/2 g_s ((T0_N - T_g) + (T1_N - T_g)) and equals the enthalpy drop. 1e-12."""
    shells, dt, gas = 8, 0.05, 25.0
    model = pi_mod.SphereConduction(NPK, shells)
    start = np.linspace(90.0, 70.0, shells)
    new, heat = model.step(start, h, gas, dt)
    volumes, c, mat, g_s = _dense_shells(NPK.radius, shells, K_NPK, RHO_C, h)
    rhs = (np.diag(c) + 0.5 * dt * mat) @ start
    rhs[-1] += dt * g_s * gas
    expected = np.linalg.solve(np.diag(c) - 0.5 * dt * mat, rhs)
    np.testing.assert_allclose(new, expected, rtol=1e-12)
    q = 0.5 * dt * g_s * ((start[-1] - gas) + (expected[-1] - gas))
    assert heat == pytest.approx(q, rel=1e-11, abs=1e-300)
    drop = model.enthalpy(start) - model.enthalpy(new)  # J, of ~1.3 J: round-off 1e-16 J
    assert drop == pytest.approx(q, rel=1e-10, abs=1e-14), "heat = enthalpy drop"
    _close(model.mean_temperature(start), float(volumes @ start / volumes.sum()), 1e-14, "mean")
    if h > 0.0:
        _close(model.surface_conductance(h), g_s, 1e-12, "surface conductance")
    else:
        with warnings.catch_warnings():  # insulated: no division by h = 0
            warnings.simplefilter("error")
            assert model.surface_conductance(h) == 0.0


@pytest.mark.parametrize(("h", "expected"), [
    (0.0, 70.0),  # insulated: the outer shell
    (0.5, 25.0 + 45.0 / (1.0 + 0.5 * 1.6875e-4 / 0.37192)),  # dr = 1.35e-3 / 8
    (400.0, 25.0 + 45.0 / (1.0 + 400.0 * 1.6875e-4 / 0.37192)),  # share 0.181491
    (math.inf, 25.0),  # the surface held at the gas temperature
])
def test_sphere_surface_temperature_closed_form(h: float, expected: float) -> None:
    """As the batch: T_s = T_g + (T_N - T_g) / (1 + h dr / (2 k)), T_N = 70, T_g = 25."""
    model = pi_mod.SphereConduction(NPK, 8)
    temps = np.linspace(90.0, 70.0, 8)
    _close(model.surface_temperature(temps, h, 25.0), expected, 1e-12, f"surface at h = {h}")


def test_default_step_and_advance_step_count() -> None:
    """default_step = dr^2 / (4 alpha) = (1.35e-3 / 20)^2 / (4 * 1.208593e-7) = 9.424701e-3 s
    for 20 shells. advance(0.1 s) then takes ceil(0.1 / 9.424701e-3) = ceil(10.61) = 11 equal
    steps: the dense solve repeated 11 times at dt = 0.1 / 11 (1e-12)."""
    model = pi_mod.SphereConduction(NPK, 20)
    _close(model.default_step, 9.424701e-3, 1e-6, "default step")
    start = np.linspace(90.0, 60.0, 20)
    final, heat = model.advance(start, 80.0, 30.0, 0.1)
    _, c, mat, g_s = _dense_shells(NPK.radius, 20, K_NPK, RHO_C, 80.0)
    dt, total = 0.1 / 11, 0.0
    temps: np.ndarray = start.copy()
    for _ in range(11):
        rhs = (np.diag(c) + 0.5 * dt * mat) @ temps
        rhs[-1] += dt * g_s * 30.0
        new = np.linalg.solve(np.diag(c) - 0.5 * dt * mat, rhs)
        total += 0.5 * dt * g_s * ((temps[-1] - 30.0) + (new[-1] - 30.0))
        temps = new
    np.testing.assert_allclose(final, temps, rtol=1e-12)
    _close(heat, total, 1e-11, "heat over the steps")
    same, none = model.advance(start, 80.0, 30.0, 0.0)
    assert none == 0.0 and np.array_equal(same, start) and same is not start


def test_series_at_biot_one_is_the_closed_form() -> None:
    """Bi = 1: z_n = (2n - 1) pi / 2 exactly, and the series mean is theta(Fo) written out
    (module docstring of this file); at Fo = 0.4 the first term alone is
    (96 / pi^4) exp(-pi^2 0.1) = 0.985534 * 0.372708 = 0.367317 (+ 1.5e-4 from the rest).
    1e-10; the lumped limit at h = 50: 30 + 60 exp(-50 * 6 / (1050 * 1465.38 * 0.0027) * 10)
    = 30 + 60 exp(-0.722129) = 59.142871."""
    np.testing.assert_allclose(pi_mod.sphere_eigenvalues(1.0, 6),
                               [(2 * n - 1) * math.pi / 2 for n in range(1, 7)], rtol=1e-13)
    h = NPK.conductivity / NPK.radius  # Bi = 1
    for fo in (0.02, 0.4, 1.5):
        t = fo * NPK.radius**2 / NPK.diffusivity
        mean = float(pi_mod.series_mean_temperature(NPK, h, 90.0, 30.0, t)[0])
        _close(mean - 30.0, 60.0 * _theta_bi1(fo, terms=400), 1e-10, f"series at Fo = {fo}")
    _close(float(pi_mod.lumped_mean_temperature(NPK, 50.0, 90.0, 30.0, 10.0)[0]), 59.142871,
           1e-7, "lumped limit")


@pytest.mark.parametrize(("duration", "steps"), [(1.0, 5), (0.1, 1)])
def test_advance_over_one_second_and_under_one_step(duration: float, steps: int) -> None:
    """4 shells: default_step = (1.35e-3 / 4)^2 / (4 * 1.208593e-7) = 0.235618 s, so 1 s is
    ceil(4.244) = 5 steps of 0.2 s and 0.1 s is one step of 0.1 s: the dense solve repeated
    (1e-12)."""
    model = pi_mod.SphereConduction(NPK, 4)
    _close(model.default_step, 0.235618, 1e-5, "default step, 4 shells")
    start = np.array([90.0, 88.0, 85.0, 80.0])
    final, heat = model.advance(start, 120.0, 30.0, duration)
    _, c, mat, g_s = _dense_shells(NPK.radius, 4, K_NPK, RHO_C, 120.0)
    dt, total = duration / steps, 0.0
    temps: np.ndarray = start.copy()
    for _ in range(steps):
        rhs = (np.diag(c) + 0.5 * dt * mat) @ temps
        rhs[-1] += dt * g_s * 30.0
        new = np.linalg.solve(np.diag(c) - 0.5 * dt * mat, rhs)
        total += 0.5 * dt * g_s * ((temps[-1] - 30.0) + (new[-1] - 30.0))
        temps = new
    np.testing.assert_allclose(final, temps, rtol=1e-12)
    _close(heat, total, 1e-11, f"heat over {duration} s")
