"""Initial particle placement: exactly the requested count, no overlaps, clear of the walls.

Particles are put on a face-centred-cubic lattice filling the drum from the bottom, the way a
settled bed lies, with a small gap between neighbours. Dropping soft particles from a height
(a random injector above the bed) sends them into the mesh at speed, and we saw 8 of 230,230
soft particles dropped from a lattice leak through a 3 m shell within 2,500 steps; a bed
placed near its rest position settles by only a fraction of a diameter. Writing positions to a
LIGGGHTS data file also makes the count exact by construction.

Equal spheres on a lattice are a crystal, which a drum without lifters does not break up
quickly, while a poured bed of equal beads (a rolling-drum experiment) is random.
``particles.placement = "random"`` places them instead by random sequential addition
(:func:`random_packing`): uniform random centres, each kept only if it overlaps none kept
before, at a loose solids fraction (:data:`RANDOM_SOLIDS_FRACTION`, below the 0.38 where
addition jams) over the lowest part of the drum that holds them; the bed then settles into a
random packing, each sphere falling at most about the loose bed's height.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from drumflow.errors import InsertionError
from drumflow.geometry.lifters import distance_to_lifters

if TYPE_CHECKING:
    from drumflow.case import Case

#: Gap between neighbouring lattice spheres, in diameters: no initial overlap, and a settling
#: drop of at most a few percent of a diameter per layer.
LATTICE_GAP = 0.02
#: Clearance from shell, lifters and end planes, in diameters.
WALL_CLEARANCE = 0.05
#: Solids fraction of the loose random packing: random sequential addition of equal spheres
#: jams near 0.38 (Torquato, Random Heterogeneous Materials, 2002), so 0.30 fills quickly.
RANDOM_SOLIDS_FRACTION = 0.30
#: Candidate centres per missing sphere in each round of random sequential addition.
CANDIDATES_PER_SPHERE = 4
#: Rounds without progress after which the region grows by one diameter.
STALLED_ROUNDS = 3


def _fcc_lattice(spacing: float, lo: NDArray, hi: NDArray) -> NDArray[np.float64]:
    """FCC sites with nearest-neighbour distance ``spacing`` inside the box [lo, hi]."""
    a = spacing * math.sqrt(2.0)  # cubic cell edge for nearest-neighbour distance `spacing`
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) * a
    n = np.ceil((hi - lo) / a).astype(int) + 1
    grid = np.stack(np.meshgrid(*[np.arange(k) for k in n], indexing="ij"), axis=-1).reshape(-1, 3)
    sites = (grid[:, None, :] * a + basis[None, :, :]).reshape(-1, 3) + lo
    inside = ((sites >= lo) & (sites <= hi)).all(axis=1)
    return sites[inside]


def place_particles(case: Case, count: int | None = None) -> NDArray[np.float64]:
    """Positions (n, 3) of the initial bed, lowest sites first.

    Raises
    ------
    InsertionError
        When fewer sites than particles fit in the free drum volume.
    """
    n = case.particle_count if count is None else count
    if case.particles.placement == "random":
        return random_packing(case, n)
    d = case.particles.diameter
    R = case.drum.radius
    length = case.drum.length
    clearance = (0.5 + WALL_CLEARANCE) * d
    lo = np.array([-R + clearance, -R + clearance, clearance])
    hi = np.array([R - clearance, R - clearance, length - clearance])
    sites = _fcc_lattice((1.0 + LATTICE_GAP) * d, lo, hi)
    r = np.hypot(sites[:, 0], sites[:, 1])
    sites = sites[r <= R - clearance]
    if case.lifters.count:
        free = distance_to_lifters(sites[:, :2], R, case.lifters) >= clearance
        sites = sites[free]
    if len(sites) < n:
        raise InsertionError(
            n, len(sites), "reduce particles.count (or fill_fraction) or use a longer drum section"
        )
    # Lowest first, and within a layer in a fixed order, so that the bed is compact and the
    # placement is reproducible; the tilt is handled by gravity once the run starts.
    order = np.lexsort((sites[:, 2], sites[:, 0], np.round(sites[:, 1] / (0.25 * d))))
    return sites[order[:n]]


def _free(points: NDArray[np.float64], case: Case, clearance: float) -> NDArray[np.bool_]:
    """Centres clear of the shell, the lifters and the end planes by ``clearance``."""
    R, length = case.drum.radius, case.drum.length
    ok = ((np.hypot(points[:, 0], points[:, 1]) <= R - clearance)
          & (points[:, 2] >= clearance) & (points[:, 2] <= length - clearance))
    if case.lifters.count and ok.any():
        ok[ok] = distance_to_lifters(points[ok, :2], R, case.lifters) >= clearance
    return ok


def random_packing(case: Case, n: int, max_rounds: int = 400) -> NDArray[np.float64]:
    """``n`` non-overlapping centres by random sequential addition, lowest first.

    The region is the drum's section below a level chosen so that ``n`` spheres fill it to
    :data:`RANDOM_SOLIDS_FRACTION` (from the segment area of the circle), raised by a diameter
    whenever :data:`STALLED_ROUNDS` rounds add nothing. Reproducible: seeded by ``run.seed``.

    Raises
    ------
    InsertionError
        When the whole drum cannot take ``n`` spheres this way within ``max_rounds`` rounds.
    """
    from scipy.spatial import cKDTree

    d = case.particles.diameter
    R, length = case.drum.radius, case.drum.length
    clearance = (0.5 + WALL_CLEARANCE) * d
    gap = (1.0 + LATTICE_GAP) * d
    rng = np.random.default_rng(case.run.seed)
    # The level whose circular segment holds the spheres at the loose fraction.
    needed = n * case.particles.volume / RANDOM_SOLIDS_FRACTION / max(length - 2 * clearance, d)
    level = -R
    while level < R and R**2 * math.acos(-level / R) + level * math.sqrt(max(R**2 - level**2, 0.0)) < needed:
        level += 0.25 * d
    kept = np.empty((0, 3))
    stalled = 0
    for _ in range(max_rounds):
        missing = n - len(kept)
        if missing <= 0:
            break
        top = min(level, R)
        m = CANDIDATES_PER_SPHERE * missing + 64
        cand = np.column_stack([rng.uniform(-R, R, m), rng.uniform(-R, top, m),
                                rng.uniform(0.0, length, m)])
        cand = cand[_free(cand, case, clearance)]
        if len(kept) and len(cand):
            near = cKDTree(kept).query(cand, k=1, distance_upper_bound=gap)[0]
            cand = cand[~np.isfinite(near)]
        # Among themselves: keep a candidate unless an earlier one of this round is too near.
        keep = np.ones(len(cand), dtype=bool)
        for i, j in sorted(cKDTree(cand).query_pairs(gap)) if len(cand) > 1 else ():
            if keep[i]:
                keep[j] = False
        added = cand[keep][:missing]
        kept = np.vstack([kept, added])
        stalled = stalled + 1 if len(added) < max(1.0, 0.01 * missing) else 0
        if stalled >= STALLED_ROUNDS:
            level, stalled = level + d, 0
    if len(kept) < n:
        raise InsertionError(n, len(kept), "random placement: use particles.placement = 'lattice', "
                             "or fewer particles")
    return kept[np.argsort(kept[:, 1], kind="stable")]


def write_data_file(case: Case, positions: NDArray[np.float64], path: Path, box: tuple) -> None:
    """Write a LIGGGHTS ``read_data`` file (atom_style granular) with the particles.

    Atom type 1 is the particles, type 2 the walls (so that per-type material tables have both).
    Columns for granular atoms: id type diameter density x y z.
    """
    lo, hi = box
    n = len(positions)
    header = (
        f"LIGGGHTS data file written by drumflow for case {case.name}\n\n"
        f"{n} atoms\n2 atom types\n\n"
        f"{lo[0]:.9g} {hi[0]:.9g} xlo xhi\n{lo[1]:.9g} {hi[1]:.9g} ylo yhi\n"
        f"{lo[2]:.9g} {hi[2]:.9g} zlo zhi\n\nAtoms\n\n"
    )
    ids = np.arange(1, n + 1)
    table = np.column_stack(
        [
            ids,
            np.ones(n),
            np.full(n, case.particles.diameter),
            np.full(n, case.particles.density),
            positions,
        ]
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w") as fh:
        fh.write(header)
        np.savetxt(fh, table, fmt=["%d", "%d", "%.9g", "%.9g", "%.9g", "%.9g", "%.9g"])
