"""Impact speeds measured from DEM snapshots, and the time step they allow (issue 11, lever 3).

The DEM step of the paper cases is capped so that a Hertz contact at the free-fall speed across
the drum, ``sqrt(2 g D)`` (7.67 m/s for a 3 m drum), lasts
:data:`~drumflow.dem.timestep.MIN_STEPS_PER_CONTACT` steps. That speed is a bound; this module
measures the speeds at which contacts actually start, so the step can be set by the impacts that
happen (Hertz contact time scales as ``v^(-1/5)``).

Method
------
For one snapshot (positions, velocities and radii of every particle at one instant):

1. **Pairs about to collide.** ``scipy.spatial.cKDTree`` lists every pair whose surface gap
   ``s = |x_j - x_i| - (r_i + r_j)`` lies in ``0 <= s <= g_max`` (``g_max`` a small fraction of
   a diameter). With the unit normal ``n = (x_j - x_i) / |x_j - x_i|``, the relative normal
   velocity is ``v_n = (v_j - v_i) . n``; a pair with ``v_n < 0`` approaches and, flying
   straight, touches after ``s / |v_n|``, at approach speed ``|v_n|``. (Spin does not enter:
   for spheres it moves the contact point only tangentially.) Pairs already in contact
   (``s < 0``) or moving apart are not impacts.
2. **Rate weighting.** Pairs approaching at speed ``v`` cross the gap ``s = 0`` at a rate
   (number in the window at speed v) x ``v / g_max``: a fast pair spends less time in the
   window, so a snapshot under-counts fast impacts by ``1/v``. Each pair therefore gets weight
   ``|v_n|``; the weighted distribution is the distribution of speeds over impacts (per unit
   time), and ``sum(|v_n|) / g_max`` is the impact rate (impacts per second). This holds when
   the pairs' gaps are spread evenly over the window, which the result's independence of
   ``g_max`` checks.
3. **Gravity across the gap** is left out. Two particles in free fall have no relative
   acceleration; a particle falling onto a supported one gains at most
   ``sqrt(v^2 + 2 g g_max) - v``: 0.2 m/s for a pair starting at rest over 2 mm, but 0.02 m/s at
   1 m/s and under 0.01 m/s above 2 m/s, the speeds that set the time step.
4. **Walls.** The drum shell is a cylinder of radius ``R`` turning about its own axis (``z``):
   its surface moves tangentially, so its normal velocity is zero and a particle's impact speed
   on it is its outward radial velocity, counted when its gap ``R - r_xy - r`` is in the window.
   The flat end plates ``z = z_min, z_max`` are static. Lifters (moving plates) are not counted.
   A sphere on a wall of the same modulus has ``m* = m``, ``R* = r`` instead of ``m/2``,
   ``r/2``, so its Hertz contact lasts ``2^(1/5)`` times as long as a sphere-sphere contact at
   the same speed: the same as a sphere-sphere contact at half the speed
   (:data:`WALL_EQUIVALENT_SPEED_FACTOR`), which lets wall and particle impacts be pooled by
   contact time.
5. **Quantiles and steps.** Weighted quantiles (inverse of the weighted distribution function)
   of the approach speed; the step that resolves a contact at speed ``v`` with ``N`` steps is
   ``t_H(v) / N`` with :func:`drumflow.dem.timestep.hertz_contact_time`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from drumflow.dem.timestep import MIN_STEPS_PER_CONTACT, hertz_contact_time
from drumflow.errors import AnalysisInputError

#: A sphere-wall Hertz contact (same modulus) at speed v lasts as long as a sphere-sphere
#: contact at this fraction of v: t ~ (m*^2 / (R* v))^(1/5), and (m*, R*) double on a wall.
WALL_EQUIVALENT_SPEED_FACTOR = 0.5


@dataclass(frozen=True)
class ImpactSample:
    """Contacts about to start at one instant (or pooled instants).

    Attributes
    ----------
    speed
        Approach speed of each pair (or particle and wall) at the moment it was seen, m/s, > 0.
    weight
        Its share of the impact rate, m/s: equal to ``speed`` (see the module docstring).
    gap_max
        The gap window the pairs were taken from, m.
    instants
        How many snapshots the sample pools.
    """

    speed: NDArray[np.float64]
    weight: NDArray[np.float64]
    gap_max: float
    instants: int = 1

    def __len__(self) -> int:
        return len(self.speed)

    @property
    def rate(self) -> float:
        """Impacts per second (averaged over the pooled instants)."""
        return float(np.sum(self.weight)) / self.gap_max / max(self.instants, 1)


def _check_gap(gap_max: float) -> None:
    if not (np.isfinite(gap_max) and gap_max > 0.0):
        raise AnalysisInputError("gap_max", gap_max, "a finite gap > 0 m")


def _as_particles(
    positions: ArrayLike, velocities: ArrayLike, radii: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    x = np.asarray(positions, dtype=np.float64)
    v = np.asarray(velocities, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise AnalysisInputError("positions", f"array of shape {x.shape}", "an (n, 3) array")
    if v.shape != x.shape:
        raise AnalysisInputError("velocities", f"array of shape {v.shape}", f"shape {x.shape}")
    r = np.asarray(radii, dtype=np.float64)
    if r.ndim == 0:
        r = np.full(len(x), float(r))
    if r.shape != (len(x),):
        raise AnalysisInputError("radii", f"array of shape {r.shape}", f"a scalar or shape ({len(x)},)")
    if len(r) and not np.all(r > 0.0):
        raise AnalysisInputError("radii", float(np.min(r)), "radii > 0 m")
    return x, v, r


def _sample(speed: NDArray[np.float64], gap_max: float) -> ImpactSample:
    speed = np.ascontiguousarray(speed, dtype=np.float64)
    return ImpactSample(speed=speed, weight=speed.copy(), gap_max=gap_max)


def snapshot_kinematics(
    columns: Mapping[str, NDArray[np.float64]],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Centres ``(n, 3)``, velocities ``(n, 3)`` and radii ``(n,)`` from a snapshot's columns
    (``x y z vx vy vz radius``, as :func:`drumflow.dem.dumps.read_dump` gives them)."""
    return (np.column_stack([columns["x"], columns["y"], columns["z"]]),
            np.column_stack([columns["vx"], columns["vy"], columns["vz"]]),
            np.asarray(columns["radius"], dtype=float))


def approaching_pairs(
    positions: ArrayLike, velocities: ArrayLike, radii: ArrayLike, gap_max: float
) -> ImpactSample:
    """Particle pairs about to collide: gap in ``[0, gap_max]`` and closing.

    Parameters
    ----------
    positions, velocities
        Centres (m) and velocities (m/s), shape ``(n, 3)``.
    radii
        Radius of each particle (m), shape ``(n,)`` or a scalar.
    gap_max
        Widest surface gap counted, m.

    Returns
    -------
    ImpactSample
        The approach speed ``-(v_j - v_i) . n`` of every closing pair, weighted by itself.

    Raises
    ------
    AnalysisInputError
        On a non-positive gap, mismatched shapes or a non-positive radius.
    """
    _check_gap(gap_max)
    x, v, r = _as_particles(positions, velocities, radii)
    if len(x) < 2:
        return _sample(np.empty(0), gap_max)
    tree = cKDTree(x)
    pairs = tree.query_pairs(2.0 * float(r.max()) + gap_max, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    d = x[j] - x[i]
    dist = np.sqrt(np.einsum("ij,ij->i", d, d))
    gap = dist - (r[i] + r[j])
    near = (gap >= 0.0) & (gap <= gap_max)
    i, j, d, dist = i[near], j[near], d[near], dist[near]
    v_n = np.einsum("ij,ij->i", v[j] - v[i], d) / dist
    return _sample(-v_n[v_n < 0.0], gap_max)


def wall_approaches(
    positions: ArrayLike,
    velocities: ArrayLike,
    radii: ArrayLike,
    gap_max: float,
    drum_radius: float,
    z_min: float,
    z_max: float,
) -> ImpactSample:
    """Particles about to hit the drum shell (radius ``drum_radius`` about z) or an end plate.

    The shell turns about its own axis, so its normal velocity is zero and the impact speed is
    the particle's outward radial velocity; the end plates ``z = z_min`` and ``z = z_max`` are
    static. Lifters are not included.

    Parameters
    ----------
    positions, velocities, radii
        As for :func:`approaching_pairs`.
    gap_max
        Widest gap counted, m.
    drum_radius
        Inner radius of the shell, m.
    z_min, z_max
        Positions of the end plates, m.

    Returns
    -------
    ImpactSample
        One entry per particle and wall it approaches within the window.

    Raises
    ------
    AnalysisInputError
        On a non-positive gap or radius, mismatched shapes, or ``z_max <= z_min``.
    """
    _check_gap(gap_max)
    if not drum_radius > 0.0:
        raise AnalysisInputError("drum_radius", drum_radius, "a radius > 0 m")
    if not z_max > z_min:
        raise AnalysisInputError("z_max", z_max, f"a plate position > z_min = {z_min:g} m")
    x, v, r = _as_particles(positions, velocities, radii)
    r_xy = np.hypot(x[:, 0], x[:, 1])
    safe = np.where(r_xy > 0.0, r_xy, 1.0)
    v_out = (x[:, 0] * v[:, 0] + x[:, 1] * v[:, 1]) / safe  # radial velocity, outward > 0
    speeds = []
    for gap, closing in (
        (drum_radius - r_xy - r, v_out),
        (x[:, 2] - r - z_min, -v[:, 2]),
        (z_max - x[:, 2] - r, v[:, 2]),
    ):
        hit = (gap >= 0.0) & (gap <= gap_max) & (closing > 0.0)
        speeds.append(closing[hit])
    return _sample(np.concatenate(speeds), gap_max)


def pool(
    samples: Sequence[ImpactSample],
    speed_factors: Sequence[float] | None = None,
    instants: int | None = None,
) -> ImpactSample:
    """Pool samples taken with the same gap window.

    Parameters
    ----------
    samples
        Samples with a common ``gap_max``.
    speed_factors
        Optional factor per sample applied to its speeds (not its weights), e.g.
        :data:`WALL_EQUIVALENT_SPEED_FACTOR` to put wall impacts on the sphere-sphere
        contact-time scale.
    instants
        Distinct instants the pool covers; by default the samples' instants add up (right for
        successive snapshots, not for pair and wall samples of the same snapshot).

    Raises
    ------
    AnalysisInputError
        On an empty list, mixed windows, or a factor list of the wrong length.
    """
    if not samples:
        raise AnalysisInputError("samples", "[]", "at least one sample")
    gaps = {s.gap_max for s in samples}
    if len(gaps) != 1:
        raise AnalysisInputError("samples", f"gap windows {sorted(gaps)}", "one common gap_max")
    factors = list(speed_factors) if speed_factors is not None else [1.0] * len(samples)
    if len(factors) != len(samples):
        raise AnalysisInputError("speed_factors", len(factors), f"{len(samples)} factors")
    return ImpactSample(
        speed=np.concatenate([s.speed * f for s, f in zip(samples, factors, strict=True)]),
        weight=np.concatenate([s.weight for s in samples]),
        gap_max=samples[0].gap_max,
        instants=instants if instants is not None else sum(s.instants for s in samples),
    )


def weighted_quantiles(values: ArrayLike, weights: ArrayLike, q: ArrayLike) -> NDArray[np.float64]:
    """Quantiles of a weighted sample: the smallest value whose weighted CDF reaches ``q``.

    Parameters
    ----------
    values, weights
        The sample and its non-negative weights (same length).
    q
        Probabilities in ``(0, 1]``; ``1`` gives the largest value of positive weight.

    Returns
    -------
    numpy.ndarray
        One value per ``q``; NaN for all when the total weight is zero.

    Raises
    ------
    AnalysisInputError
        On mismatched lengths, negative weights or ``q`` outside ``(0, 1]``.
    """
    x = np.asarray(values, dtype=np.float64).ravel()
    w = np.asarray(weights, dtype=np.float64).ravel()
    p = np.atleast_1d(np.asarray(q, dtype=np.float64))
    if x.shape != w.shape:
        raise AnalysisInputError("weights", f"{w.size} weights", f"{x.size}, one per value")
    if w.size and not np.all(w >= 0.0):
        raise AnalysisInputError("weights", float(np.min(w)), "weights >= 0")
    if not np.all((p > 0.0) & (p <= 1.0)):
        raise AnalysisInputError("q", p.tolist(), "probabilities in (0, 1]")
    if w.size == 0 or not np.sum(w) > 0.0:
        return np.full(p.shape, np.nan)
    order = np.argsort(x, kind="stable")
    cum = np.cumsum(w[order])
    idx = np.searchsorted(cum, p * cum[-1], side="left")
    out: NDArray[np.float64] = x[order][np.minimum(idx, len(x) - 1)]
    return out


def implied_time_steps(
    speeds: ArrayLike,
    radius: float,
    density: float,
    youngs_modulus: float,
    poisson: float,
    steps_per_contact: float = MIN_STEPS_PER_CONTACT,
    contact: Literal["particle", "wall"] = "particle",
) -> NDArray[np.float64]:
    """Time step that resolves a Hertz contact at each impact speed with ``steps_per_contact``.

    ``t_H(v) / steps_per_contact`` with :func:`~drumflow.dem.timestep.hertz_contact_time`;
    for ``contact="wall"`` the sphere-wall contact of a wall with the particles' modulus, which
    equals the sphere-sphere one at ``WALL_EQUIVALENT_SPEED_FACTOR * v``. Scales as
    ``v^(-1/5)``.

    Raises
    ------
    AnalysisInputError
        On non-positive speeds or steps per contact, or an unknown contact kind.
    """
    v = np.atleast_1d(np.asarray(speeds, dtype=np.float64))
    if not np.all(v > 0.0):
        raise AnalysisInputError("speeds", float(np.min(v)), "speeds > 0 m/s")
    if not steps_per_contact > 0.0:
        raise AnalysisInputError("steps_per_contact", steps_per_contact, "a number > 0")
    if contact not in ("particle", "wall"):
        raise AnalysisInputError("contact", contact, "'particle' or 'wall'")
    factor = WALL_EQUIVALENT_SPEED_FACTOR if contact == "wall" else 1.0
    return np.array(
        [
            hertz_contact_time(radius, density, youngs_modulus, poisson, factor * float(s))
            / steps_per_contact
            for s in v
        ]
    )
