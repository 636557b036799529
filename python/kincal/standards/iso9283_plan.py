"""`kincal accuracy plan-iso9283`: the ISO 9283 test poses and their 30-cycle pose program.

ISO 9283:1998 6.2: a cube inside the working space, edges parallel to the base frame, of the largest
volume the robot reaches; the test plane is one of its diagonal planes, P1 at the cube's centre and
P2..P5 on the diagonals of that plane at 10% of the diagonal's length from the corners (so P_k =
centre + 0.8 (corner_k - centre)); every pose at one orientation (here the tool's orientation at the
robot's home pose unless given). The plane used is the one through the cube's bottom edge at -y and
its top edge at +y (in cube coordinates: y = z); P2 (+,+,+) and P3 (-,+,+) near its top corners, P4
(-,-,-) and P5 (+,-,-) near the bottom ones. The cycle is P1 -> P5 -> P4 -> P3 -> P2 -> P1.

"Fits" means: every point of an 11 x 11 x 11 lattice over the cube (corners, edges, faces and
inside) has an inverse-kinematics solution within the joint limits at the orientation (the robot's
closed-form IK). The largest cube: the reachable set sampled on a voxel grid, the largest cube of
reachable voxels, then its centre and edge refined on the continuous lattice test (pattern search
over the centre, bisection over the edge to 0.1%); of the cubes within 1% of the largest found (a
robot's workspace is nearly symmetric about its first axis), the one nearest the tool's home
position."""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING, Any, Optional, Sequence, Union

import numpy as np

from .. import _core, fk
from ..io.csv_text import format_rows

if TYPE_CHECKING:
    from ..typing_ import BoolArray, FloatArray

VOXELS = 48          # voxels along the largest extent of the robot's reach
SEARCH_LATTICE = 7   # lattice points per edge while searching
FINAL_LATTICE = 11   # lattice points per edge of the final test (the definition of "fits")
ORDER = ["P1", "P5", "P4", "P3", "P2"]
CORNERS = {"P2": (1, 1, 1), "P3": (-1, 1, 1), "P4": (-1, -1, -1), "P5": (1, -1, -1)}


class Reach:
    """Reachability of tool positions at one orientation within the joint limits (closed-form IK)."""

    def __init__(self, robot: _core.Robot, abc: Union[FloatArray, Sequence[float]],
                 z_min: Optional[float] = None) -> None:
        if not robot.closed_form_ik:
            raise ValueError(f"{robot.name}: plan-iso9283 needs the closed-form IK, which this robot has not "
                             f"({robot.ik_reason})")
        self.robot, self.abc, self.z_min = robot, np.asarray(abc, dtype=float), z_min
        self.ref = np.asarray(robot.home_deg or [0.0] * robot.dof, dtype=float)

    def one(self, p: FloatArray) -> bool:
        if self.z_min is not None and p[2] < self.z_min:
            return False
        return _core.ik_nearest(self.robot, np.concatenate((p, self.abc)), self.ref) is not None

    def many(self, pts: FloatArray) -> BoolArray:
        return np.fromiter((self.one(p) for p in pts), dtype=bool, count=len(pts))

    def all(self, pts: FloatArray) -> bool:
        return all(self.one(p) for p in pts)


def lattice(centre: FloatArray, edge: float, k: int) -> FloatArray:
    """k^3 points over the cube, its corners first (a cube that does not fit fails there most often)."""
    u = np.linspace(-0.5, 0.5, k)
    g = np.array(list(itertools.product(u, u, u)))
    corner = np.all(np.abs(np.abs(g) - 0.5) < 1e-12, axis=1)
    g = np.vstack([g[corner], g[~corner]])
    return np.asarray(centre, dtype=float) + edge * g


def fits(reach: Reach, centre: FloatArray, edge: float, k: int = FINAL_LATTICE) -> bool:
    return reach.all(lattice(centre, edge, k))


def working_orientation(robot: _core.Robot) -> FloatArray:
    """The tool's orientation (ABC, deg) at the robot's home pose."""
    return np.round(fk(robot, [robot.home_deg or [0.0] * robot.dof])[0, 3:], 9) + 0.0


def _voxel_cube(reach: Reach, seed: int) -> tuple[FloatArray, float, float]:
    """The reachable set on a voxel grid over the tool's reach, and the largest cubes of reachable
    voxels: (candidate centres, their edge in mm, the voxel size)."""
    rng = np.random.default_rng(seed)
    lim = np.asarray(reach.robot.limits_deg)
    q = rng.uniform(lim[:, 0], lim[:, 1], size=(20000, reach.robot.dof))
    xyz = fk(reach.robot, q)[:, :3]
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    h = float((hi - lo).max()) / VOXELS
    axes = [np.arange(a - h, b + 1.5 * h, h) for a, b in zip(lo, hi)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    occ = reach.many(grid).reshape([len(a) for a in axes])
    if not occ.any():
        raise ValueError(f"{reach.robot.name}: no position is reachable within the joint limits at orientation "
                         f"a,b,c = {', '.join(f'{v:g}' for v in reach.abc)}")

    def corners(s: int) -> BoolArray:  # low corners of fully reachable s x s x s blocks
        m: BoolArray = occ
        for ax in range(3):
            m = np.asarray(np.lib.stride_tricks.sliding_window_view(m, s, axis=ax).all(axis=-1))
        return m

    best, top = 1, min(occ.shape)
    while best < top:  # largest s with a block (monotone: a block of s holds one of s - 1)
        mid = (best + top + 1) // 2
        if corners(mid).any():
            best = mid
        else:
            top = mid - 1
    idx = np.argwhere(corners(best))
    centres = np.array([[axes[d][i] for d, i in enumerate(r)] for r in idx]) + (best - 1) * h / 2
    # a few of them, spread (farthest-point sampling from the one nearest their mean)
    pick = [int(np.argmin(np.linalg.norm(centres - centres.mean(axis=0), axis=1)))]
    dist = np.linalg.norm(centres - centres[pick[0]], axis=1)
    while len(pick) < min(6, len(centres)) and dist.max() > h:
        pick.append(int(np.argmax(dist)))
        dist = np.minimum(dist, np.linalg.norm(centres - centres[pick[-1]], axis=1))
    return centres[pick], (best - 1) * h, h


def _largest_edge(reach: Reach, c: FloatArray, start: float, k: int, rel: float = 1e-3) -> float:
    """The largest edge of a cube centred at ``c`` that fits (on a k-lattice), by bisection."""
    lo, hi = 0.0, max(start, 1.0)
    if fits(reach, c, hi, k):
        lo = hi
        hi *= 1.25
        while fits(reach, c, hi, k):
            lo, hi = hi, hi * 1.25
    elif not reach.one(c):
        return 0.0
    while hi - lo > rel * max(lo, 1.0):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if fits(reach, c, mid, k) else (lo, mid)
    return lo


def _refine(reach: Reach, c: FloatArray, edge: float, step: float, k: int) -> tuple[FloatArray, float]:
    """Pattern search over the centre (26 directions, halving steps): the largest cube near ``c``."""
    edge = _largest_edge(reach, c, edge, k)
    dirs = np.array([d for d in itertools.product((-1, 0, 1), repeat=3) if any(d)], dtype=float)
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    while step > 2e-3 * max(edge, 1.0):
        moved = False
        for d in dirs:
            c2 = c + step * d
            if fits(reach, c2, edge * 1.002, k):  # larger here: how much larger
                e2 = _largest_edge(reach, c2, edge * 1.002, k)
                if e2 > edge:
                    c, edge, moved = c2, e2, True
                    break
        if not moved:
            step /= 2
    return c, edge


def largest_cube(reach: Reach, seed: int = 0) -> tuple[FloatArray, float]:
    """(centre, edge): the largest cube that fits (on the final lattice)."""
    cands, edge0, h = _voxel_cube(reach, seed)
    found = [_refine(reach, c, edge0, h / 2, SEARCH_LATTICE) for c in cands]
    top = max(e for _, e in found)
    # the workspace of a robot is nearly symmetric about its first axis: of the cubes within 1% of
    # the largest, the one nearest the tool's home position (in front of the robot)
    home = fk(reach.robot, reach.ref[None, :])[0, :3]
    c, e = min((f for f in found if f[1] >= 0.99 * top), key=lambda f: float(np.linalg.norm(f[0] - home)))
    return c, _largest_edge(reach, c, e, FINAL_LATTICE)


def iso_poses(centre: FloatArray, edge: float, abc: FloatArray) -> dict[str, FloatArray]:
    """P1..P5 (x,y,z,a,b,c) of the cube of ``edge`` centred at ``centre``."""
    out = {"P1": np.r_[centre, abc]}
    for name, s in CORNERS.items():
        out[name] = np.r_[np.asarray(centre) + 0.8 * (edge / 2) * np.asarray(s, dtype=float), abc]
    return {k: out[k] for k in ("P1", "P2", "P3", "P4", "P5")}


def program_rows(poses: dict[str, FloatArray], cycles: int) -> list[list[Union[float, str]]]:
    """The pose program: P1 (cycle 0: the start), then per cycle P5, P4, P3, P2, P1."""
    rows: list[list[Union[float, str]]] = [list(poses["P1"]) + ["P1", 0]]
    for j in range(1, cycles + 1):
        rows += [list(poses[p]) + [p, j] for p in ORDER[1:] + ["P1"]]
    return rows


def parse_triple(text: Optional[str], option: str) -> Optional[FloatArray]:
    if text is None:
        return None
    try:
        v = np.array([float(x) for x in text.split(",")])
    except ValueError:
        v = np.zeros(0)
    if len(v) != 3 or not np.all(np.isfinite(v)):
        raise ValueError(f"{option} {text}: expected three numbers, such as 180,0,180")
    return v


def plan(robot: _core.Robot, cube: Optional[float] = None, orientation: Optional[str] = None,
         z_min: Optional[float] = None, cycles: int = 30, seed: int = 0) -> dict[str, Any]:
    """The cube (largest, or of edge ``cube`` placed where the largest is), P1..P5 and the program
    rows; a cube that does not fit is an error naming --cube."""
    if cycles < 1:
        raise ValueError(f"--cycles {cycles}: at least 1")
    if cube is not None and not cube > 0:
        raise ValueError(f"--cube {cube:g}: the edge must be positive (mm)")
    abc = parse_triple(orientation, "--orientation")
    if abc is None:
        abc = working_orientation(robot)
    reach = Reach(robot, abc, z_min)
    centre, largest = largest_cube(reach, seed)
    edge = largest
    if cube is not None:
        if not fits(reach, centre, cube):
            raise ValueError(f"--cube {cube:g}: a cube of {cube:g} mm does not fit in {robot.name}'s workspace at "
                             f"orientation a,b,c = {', '.join(f'{v:g}' for v in abc)} (the largest that fits has a "
                             f"{largest:.0f} mm edge, centred at {', '.join(f'{v:.0f}' for v in centre)})")
        edge = float(cube)
    poses = iso_poses(centre, edge, abc)
    return {"centre_mm": centre, "edge_mm": edge, "largest_edge_mm": largest, "abc_deg": abc, "poses": poses,
            "rows": program_rows(poses, cycles)}


def write_plan(robot: _core.Robot, out: str, **options: Any) -> str:
    """`kincal accuracy plan-iso9283`: the program written to ``out`` (x,y,z,a,b,c, point, cycle);
    returns the summary (the cube and P1..P5)."""
    res = plan(robot, **options)
    _core.write_file_atomic(out, format_rows(["x", "y", "z", "a", "b", "c", "point", "cycle"], res["rows"]))
    c, a = res["centre_mm"], res["abc_deg"]
    lines = [f"cube: edge {res['edge_mm']:.1f} mm (largest that fits: {res['largest_edge_mm']:.1f} mm), centre "
             f"{c[0]:.1f}, {c[1]:.1f}, {c[2]:.1f} mm, orientation a,b,c {a[0]:g}, {a[1]:g}, {a[2]:g} deg"]
    lines += [f"{name}: " + ", ".join(f"{v:.3f}" for v in p) for name, p in res["poses"].items()]
    cycles = options.get("cycles", 30)
    lines.append(f"{out}: {len(res['rows'])} poses, {cycles} cycles P1 -> P5 -> P4 -> P3 -> P2 -> P1")
    return "\n".join(lines)
