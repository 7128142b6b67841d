"""Heat conduction inside a spherical particle with a convective surface: one solver for
every reduced-order cooler (curtain, whole drum, vibrating fluid bed).

The particle is split into ``shells`` concentric spherical shells of equal thickness
(the "concentric spherical shells" of the fluid-bed source, and the radial grid of Wardjiman
and Rhodes 2009 for the curtain). Each shell is one finite volume; neighbouring shells
exchange ``k A (T_i - T_{i+1}) / dr`` across their common sphere, and the outer shell loses
``(T_N - T_gas) / (1/(h A_s) + (dr/2)/(k A_s))`` to the gas through its half-shell and the
film. Time integration is Crank-Nicolson (second order, unconditionally stable), so a step
is one tridiagonal solve (:func:`scipy.linalg.solve_banded`).

Why finite volumes rather than finite differences in u = T r: the two discretise the same
equation, but the shell balance conserves energy to round-off, step by step (the heat a
step removes equals the shell enthalpy change exactly), which is what lets every cooler
model close its energy balance to 1e-9. The u = T r form does not.

The analytic series solution of a sphere in a fluid at constant h (Carslaw and Jaeger 1959,
sec. 9.4; Incropera et al., eq. 5.50) is :func:`series_mean_temperature`, used to check the
solver, and :func:`lumped_mean_temperature` the small-Biot limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import solve_banded
from scipy.optimize import brentq

from drumflow.physics.particle_air import lumped_cooling

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Sphere:
    """A spherical particle's size and properties.

    Parameters
    ----------
    diameter
        m.
    conductivity
        W/(m K).
    density
        kg/m^3.
    heat_capacity
        J/(kg K).
    """

    diameter: float
    conductivity: float
    density: float
    heat_capacity: float

    def __post_init__(self) -> None:
        for name in ("diameter", "conductivity", "density", "heat_capacity"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"Sphere.{name} = {value!r}: must be a finite number > 0")

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    @property
    def volume(self) -> float:
        return math.pi * self.diameter**3 / 6.0

    @property
    def surface(self) -> float:
        return math.pi * self.diameter**2

    @property
    def mass(self) -> float:
        return self.density * self.volume

    @property
    def diffusivity(self) -> float:
        """Thermal diffusivity k/(rho cp), m^2/s."""
        return self.conductivity / (self.density * self.heat_capacity)

    def biot(self, h: float) -> float:
        """Biot number h R / k on the radius (the series solution's definition)."""
        return h * self.radius / self.conductivity


class SphereConduction:
    """Crank-Nicolson shell model of one particle's interior.

    Parameters
    ----------
    sphere
        The particle.
    shells
        Number of concentric shells of equal thickness (>= 2). 20 shells put the mean
        temperature within 0.1% of the series solution's temperature drop for Bi <= 10
        (``tests/unit/test_particle_interior.py``).

    Notes
    -----
    Temperatures are per shell, innermost first, in any consistent unit (K or degC).
    """

    def __init__(self, sphere: Sphere, shells: int = 20) -> None:
        if shells < 2:
            raise ValueError(f"shells = {shells}: must be >= 2")
        self.sphere = sphere
        self.shells = shells
        r_out = np.linspace(0.0, sphere.radius, shells + 1)
        self.dr = sphere.radius / shells
        #: Outer radius of each shell, m.
        self.r_faces = r_out[1:]
        #: Radius of each shell's centre (mid-thickness), m.
        self.r_centres = 0.5 * (r_out[:-1] + r_out[1:])
        #: Volume of each shell, m^3.
        self.volumes = 4.0 / 3.0 * math.pi * (r_out[1:] ** 3 - r_out[:-1] ** 3)
        #: Heat capacity of each shell, J/K.
        self.capacities = sphere.density * sphere.heat_capacity * self.volumes
        # Conductance between shell i and i+1 across the sphere of radius r_faces[i], W/K.
        areas = 4.0 * math.pi * self.r_faces**2
        self._conductance = sphere.conductivity * areas[:-1] / self.dr
        self._surface_area = areas[-1]

    # -- state ---------------------------------------------------------------------------
    def uniform(self, temperature: float) -> FloatArray:
        """A particle at one temperature throughout."""
        return np.full(self.shells, float(temperature))

    def mean_temperature(self, temperatures: FloatArray) -> float:
        """Mass-weighted (caloric) mean temperature."""
        return float(np.dot(self.volumes, temperatures) / self.sphere.volume)

    def enthalpy(self, temperatures: FloatArray) -> float:
        """Sensible enthalpy relative to zero of the temperature scale, J per particle."""
        return float(np.dot(self.capacities, temperatures))

    def surface_conductance(self, h: float) -> float:
        """Conductance from the outer shell's centre through the film to the gas, W/K."""
        if h <= 0.0:
            return 0.0
        if math.isinf(h):
            return self.sphere.conductivity * self._surface_area / (0.5 * self.dr)
        return 1.0 / (1.0 / (h * self._surface_area)
                      + 0.5 * self.dr / (self.sphere.conductivity * self._surface_area))

    def surface_temperature(self, temperatures: FloatArray, h: float, gas_temperature: float) -> float:
        """Temperature at the particle surface, between the outer shell and the film."""
        g = self.surface_conductance(h)
        if g == 0.0:
            return float(temperatures[-1])
        q = g * (temperatures[-1] - gas_temperature)
        return float(gas_temperature + (q / (h * self._surface_area) if math.isfinite(h) else 0.0))

    # -- time step -----------------------------------------------------------------------
    def _operator(self, g_surface: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Diagonals of the conduction operator L (dT/dt = L T + b) scaled by capacity:
        returns (lower, main, upper) of C^-1 K."""
        n = self.shells
        c = self.capacities
        gk = self._conductance
        main = np.zeros(n)
        upper = np.zeros(n - 1)
        lower = np.zeros(n - 1)
        main[:-1] -= gk
        main[1:] -= gk
        upper[:] = gk
        lower[:] = gk
        main[-1] -= g_surface
        return lower / c[1:], main / c, upper / c[:-1]

    def step(self, temperatures: FloatArray, h: float, gas_temperature: float,
             dt: float) -> tuple[FloatArray, float]:
        """Advance one Crank-Nicolson step at a constant film coefficient and gas temperature.

        Parameters
        ----------
        temperatures
            Shell temperatures at the start of the step.
        h
            Film coefficient at the surface, W/(m^2 K); 0 for an insulated particle, ``inf``
            for a surface held at the gas temperature.
        gas_temperature
            Gas temperature for the step.
        dt
            Step, s (> 0).

        Returns
        -------
        (temperatures, heat)
            The shell temperatures at the end of the step and the heat the particle gave to
            the gas during it, J (negative when it was heated). The heat equals the drop in
            :meth:`enthalpy` to round-off.
        """
        if not dt > 0:
            raise ValueError(f"dt = {dt!r}: must be > 0")
        g = self.surface_conductance(h)
        lower, main, upper = self._operator(g)
        source = np.zeros(self.shells)
        source[-1] = g * gas_temperature / self.capacities[-1]
        # (I - dt/2 L) T1 = (I + dt/2 L) T0 + dt b
        rhs = temperatures + 0.5 * dt * (main * temperatures) + dt * source
        rhs[:-1] += 0.5 * dt * upper * temperatures[1:]
        rhs[1:] += 0.5 * dt * lower * temperatures[:-1]
        bands = np.zeros((3, self.shells))
        bands[0, 1:] = -0.5 * dt * upper
        bands[1, :] = 1.0 - 0.5 * dt * main
        bands[2, :-1] = -0.5 * dt * lower
        new = solve_banded((1, 1), bands, rhs)
        heat = 0.5 * dt * g * ((temperatures[-1] - gas_temperature) + (new[-1] - gas_temperature))
        return new, float(heat)

    def advance(self, temperatures: FloatArray, h: float, gas_temperature: float,
                duration: float, max_step: float | None = None) -> tuple[FloatArray, float]:
        """Advance ``duration`` seconds in equal steps no longer than ``max_step``.

        The default step is a quarter of the shell diffusion time dr^2/alpha, short enough
        that Crank-Nicolson's slowly decaying oscillations of the fastest shell modes stay
        below round-off in the mean temperature.

        Returns
        -------
        (temperatures, heat)
            As :meth:`step`, with the heat summed over the steps.
        """
        if duration < 0:
            raise ValueError(f"duration = {duration!r}: must be >= 0")
        if duration == 0:
            return temperatures.copy(), 0.0
        limit = max_step if max_step is not None else self.default_step
        n = max(1, math.ceil(duration / limit - 1e-12))
        dt = duration / n
        heat = 0.0
        current = temperatures
        for _ in range(n):
            current, q = self.step(current, h, gas_temperature, dt)
            heat += q
        return current, heat

    @property
    def default_step(self) -> float:
        """A quarter of the shell diffusion time dr^2/alpha, s."""
        return 0.25 * self.dr**2 / self.sphere.diffusivity


# -- references ------------------------------------------------------------------------------
def sphere_eigenvalues(biot: float, count: int) -> FloatArray:
    """Roots of 1 - z cot z = Bi (z in ((n-1) pi, n pi)), the sphere's transient modes."""
    if biot <= 0:
        raise ValueError(f"biot = {biot!r}: must be > 0")
    roots = np.empty(count)
    for n in range(1, count + 1):
        lo = (n - 1) * math.pi + 1e-12
        hi = n * math.pi - 1e-12
        roots[n - 1] = brentq(lambda z: 1.0 - z / math.tan(z) - biot, lo, hi, xtol=1e-15)
    return roots


def series_mean_temperature(sphere: Sphere, h: float, initial: float, gas: float,
                            time: float | FloatArray, terms: int = 200) -> FloatArray:
    """Mass-mean temperature of a sphere suddenly put in a fluid: the exact series solution.

    theta_mean / theta_0 = sum_n 6 Bi^2 exp(-z_n^2 Fo) / (z_n^2 (z_n^2 + Bi^2 - Bi)),
    with Fo = alpha t / R^2 and z_n the roots of 1 - z cot z = Bi (Carslaw and Jaeger 1959,
    sec. 9.4, eq. 9.4(8) integrated over the volume; Incropera et al. eqs. 5.50-5.52).
    """
    bi = sphere.biot(h)
    z = sphere_eigenvalues(bi, terms)
    fo = np.atleast_1d(np.asarray(time, dtype=float)) * sphere.diffusivity / sphere.radius**2
    coeff = 6.0 * bi**2 / (z**2 * (z**2 + bi**2 - bi))
    ratio = np.exp(-np.outer(fo, z**2)) @ coeff
    return np.asarray(gas + (initial - gas) * ratio, dtype=float)


def lumped_mean_temperature(sphere: Sphere, h: float, initial: float, gas: float,
                            time: float | FloatArray) -> FloatArray:
    """The lumped (Bi -> 0) solution: exp(-h A t / (m cp))."""
    rate = h * sphere.surface / (sphere.mass * sphere.heat_capacity)
    t = np.atleast_1d(np.asarray(time, dtype=float))
    return lumped_cooling(initial, gas, rate * t)


# -- many particles at once: the coupling loop's interior -------------------------------------
#: Relative error of the shell model's temperature drop, against the series solution, that
#: :func:`shells_for_biot` aims at: a quarter of the 0.5 % the coupled check allows, so the
#: loop's other errors (the interval's hold of h, round-off) keep their room.
SHELL_TOLERANCE = 1.25e-3
#: Fewest and most shells the rule may choose (memory: 8 bytes a shell a particle).
MIN_SHELLS, MAX_SHELLS = 3, 40


def shell_drop_error(biot: float, shells: int) -> float:
    """Relative error of the mean-temperature drop of a ``shells``-shell sphere at ``biot``.

    Measured where the series solution has removed 63.2 % of the initial excess (one lumped
    time constant's worth), on a unit sphere with unit diffusivity: the error of equal-thickness
    shells depends only on Bi and the shell count at a given fraction of the drop.
    """
    if not (math.isfinite(biot) and biot > 0):
        raise ValueError(f"biot = {biot!r}: must be a finite number > 0")
    unit = Sphere(diameter=2.0, conductivity=1.0, density=1.0, heat_capacity=1.0)
    h = biot  # Bi = h R / k with R = k = 1
    # Time of 63.2 % of the drop, from the series' mean excess (monotone in time).
    target = math.exp(-1.0)

    def excess(fo: float) -> float:
        return float(series_mean_temperature(unit, h, 1.0, 0.0, fo)[0]) - target

    hi = 1.0
    while excess(hi) > 0:
        hi *= 2.0
    t = float(brentq(excess, 1e-9, hi, xtol=1e-12))
    model = SphereConduction(unit, shells)
    final, _ = model.advance(model.uniform(1.0), h, 0.0, t, max_step=min(t / 200.0, model.default_step))
    return abs((1.0 - model.mean_temperature(final)) / (1.0 - target) - 1.0)


def shells_for_biot(biot: float, tolerance: float = SHELL_TOLERANCE) -> int:
    """Fewest shells whose drop is within ``tolerance`` of the series solution at ``biot``.

    The error of equal-thickness shells falls as 1/shells^2 and grows with Bi (measured: 5 shells
    err by 0.08 % at Bi 0.1, 0.6 % at Bi 1 and 1.4 % at Bi 3), so the count comes from the
    largest Biot number a case expects. At most :data:`MAX_SHELLS`.
    """
    for shells in range(MIN_SHELLS, MAX_SHELLS + 1):
        if shell_drop_error(biot, shells) <= tolerance:
            return shells
    return MAX_SHELLS


class ShellBatch:
    """The shell model of :class:`SphereConduction` for many particles at once.

    Each row is one particle: ``shells`` equal-thickness shells, innermost first, in the same
    finite-volume, Crank-Nicolson scheme (so a row is what :class:`SphereConduction` computes,
    to round-off, and the heat given to the gas equals the enthalpy drop of the row). Rows
    differ in radius, heat capacity, film coefficient and gas temperature; the solve is the
    Thomas algorithm vectorised over rows, a loop of ``shells`` numpy operations.

    Parameters
    ----------
    shells
        Shells per particle (>= 2).
    conductivity
        Thermal conductivity of the particles, W/(m K).
    diffusivity
        Thermal diffusivity k / (rho cp), m^2/s (sets the sub-step, :meth:`advance`).
    """

    def __init__(self, shells: int, conductivity: float, diffusivity: float) -> None:
        if shells < 2:
            raise ValueError(f"shells = {shells}: must be >= 2")
        for name, value in (("conductivity", conductivity), ("diffusivity", diffusivity)):
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r}: must be a finite number > 0")
        self.shells = shells
        self.conductivity = conductivity
        self.diffusivity = diffusivity
        faces = np.arange(shells + 1) / shells
        #: Each shell's share of the particle's volume (and heat capacity).
        self.fractions: FloatArray = faces[1:] ** 3 - faces[:-1] ** 3
        # Conductance between shells i and i+1 of a particle of radius R is k 4 pi R M r_i^2,
        # r_i the unit radius of their common face: this is the factor without k R.
        self._inner = 4.0 * math.pi * shells * faces[1:-1] ** 2

    def mean(self, temperatures: FloatArray) -> FloatArray:
        """Caloric mean temperature of each row."""
        return np.asarray(temperatures @ self.fractions, dtype=float)

    def surface_conductance(self, h: FloatArray, radius: FloatArray) -> FloatArray:
        """Conductance from the outer shell's centre through the film to the gas, W/K."""
        area = 4.0 * math.pi * radius**2
        half_shell = 0.5 * radius / self.shells / (self.conductivity * area)
        with np.errstate(divide="ignore"):
            return np.where(h > 0.0, 1.0 / (1.0 / (h * area) + half_shell), 0.0)

    def surface_temperature(self, temperatures: FloatArray, h: FloatArray, radius: FloatArray,
                            gas_temperature: FloatArray | float) -> FloatArray:
        """Temperature of each row's surface, between its outer shell and the film."""
        g = self.surface_conductance(h, radius)
        area = 4.0 * math.pi * radius**2
        outer = temperatures[:, -1]
        with np.errstate(divide="ignore", invalid="ignore"):
            film_drop = np.where(h > 0.0, g * (outer - gas_temperature) / (h * area), 0.0)
        return np.where(h > 0.0, gas_temperature + film_drop, outer)

    def add_surface_heat(self, temperatures: FloatArray, mean_rise: FloatArray) -> None:
        """Put heat that entered through the surface (contact conduction) into the outer shell,
        in place: ``mean_rise`` is the rise of each row's mean temperature it amounts to."""
        temperatures[:, -1] += mean_rise / self.fractions[-1]

    def step(self, temperatures: FloatArray, h: FloatArray, gas_temperature: FloatArray | float,
             radius: FloatArray, capacity: FloatArray, dt: float) -> tuple[FloatArray, FloatArray]:
        """One Crank-Nicolson step of every row; returns (temperatures, heat to the gas, J).

        ``capacity`` is each particle's m cp, J/K; ``h`` its film coefficient, W/(m^2 K).
        """
        new, heat = self._step_columns(np.ascontiguousarray(temperatures.T), h, gas_temperature,
                                       radius, capacity, dt)
        return np.ascontiguousarray(new.T), heat

    def _step_columns(self, t0: FloatArray, h: FloatArray, gas_temperature: FloatArray | float,
                      radius: FloatArray, capacity: FloatArray,
                      dt: float) -> tuple[FloatArray, FloatArray]:
        # Shell-major layout (m, n): every operation of the Thomas sweep runs over one
        # contiguous row of particles (4 times faster than column slices at 467,443 x 12).
        m, n = t0.shape
        c = self.fractions[:, None] * capacity[None, :]  # shell capacities, J/K
        gk = self._inner[:, None] * (self.conductivity * radius)[None, :]  # (m-1, n), W/K
        gs = self.surface_conductance(h, radius)
        tg = np.broadcast_to(np.asarray(gas_temperature, float), (n,))
        # (C - dt/2 K) T1 = (C + dt/2 K) T0 + dt gs Tg e_m, K the conduction operator.
        half = 0.5 * dt
        diff = gk * (t0[1:] - t0[:-1])  # flow from shell i+1 into shell i, W
        rhs = c * t0
        rhs[:-1] += half * diff
        rhs[1:] -= half * diff
        rhs[-1] += dt * gs * tg - half * gs * t0[-1]
        diag = c
        diag[:-1] += half * gk
        diag[1:] += half * gk
        diag[-1] += half * gs
        off = -half * gk  # the symmetric off-diagonal
        # Thomas algorithm (the matrix is diagonally dominant: no pivoting needed).
        cprime = np.empty((m - 1, n))
        dprime = np.empty((m, n))
        cprime[0] = off[0] / diag[0]
        dprime[0] = rhs[0] / diag[0]
        for i in range(1, m):
            denom = diag[i] - off[i - 1] * cprime[i - 1]
            if i < m - 1:
                cprime[i] = off[i] / denom
            dprime[i] = (rhs[i] - off[i - 1] * dprime[i - 1]) / denom
        new = dprime
        for i in range(m - 2, -1, -1):
            new[i] -= cprime[i] * new[i + 1]
        heat = half * gs * ((t0[-1] - tg) + (new[-1] - tg))
        return new, heat

    def sub_steps(self, duration: float, radius: FloatArray) -> int:
        """Equal Crank-Nicolson steps for ``duration``: none longer than a quarter of the
        thinnest shell's diffusion time, as :attr:`SphereConduction.default_step`."""
        if len(radius) == 0:
            return 1
        limit = 0.25 * (float(np.min(radius)) / self.shells) ** 2 / self.diffusivity
        return max(1, math.ceil(duration / limit - 1e-12))

    def advance(self, temperatures: FloatArray, h: FloatArray, gas_temperature: FloatArray | float,
                radius: FloatArray, capacity: FloatArray,
                duration: float) -> tuple[FloatArray, FloatArray]:
        """Advance every row ``duration`` seconds at constant h and gas temperature.

        Returns
        -------
        (temperatures, heat)
            The new shell temperatures and the heat each particle gave the gas, J.
        """
        if not duration > 0:
            raise ValueError(f"duration = {duration!r}: must be > 0")
        steps = self.sub_steps(duration, radius)
        dt = duration / steps
        heat = np.zeros(len(temperatures))
        current = np.ascontiguousarray(temperatures.T)
        for _ in range(steps):
            current, q = self._step_columns(current, h, gas_temperature, radius, capacity, dt)
            heat += q
        return np.ascontiguousarray(current.T), heat
