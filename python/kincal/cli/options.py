"""What the `kincal` commands share: the robot, effect, loss and fitting option groups, their
parsers, and the progress lines on stderr. Parsing only; the commands are in the modules beside."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Optional, Union

import numpy as np

from .. import _core, load_robot
from ..calibration import identify as ident
from ..calibration import priors
from ..calibration.effect_choice import check_data
from ..calibration.fitting import DEFAULT_LOSS_SCALE_MM, FitOptions, masses

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import FloatArray


def joint_convention_option(sp: argparse.ArgumentParser) -> None:
    sp.add_argument("--joint-convention", choices=["fanuc"],
                    help="how the controller numbers the joints of a URDF or built-in robot (a model JSON carries "
                         "its own): fanuc, J3 is the forearm's angle to the horizontal; every joint angle in the "
                         "files is then the controller's")


def robot_opts(sp: argparse.ArgumentParser) -> None:
    sp.add_argument("--robot", required=True, help="built-in name (kr500), URDF file or model JSON")
    sp.add_argument("--base", help="URDF: base link of the chain (default: the root link)")
    sp.add_argument("--tip", help="URDF: tip link of the chain (default: the only leaf)")
    joint_convention_option(sp)


def robot_of(args: argparse.Namespace) -> _core.Robot:
    """The robot of --robot (with --base, --tip, --joint-convention where the command has them)."""
    return load_robot(args.robot, getattr(args, "base", None), getattr(args, "tip", None),
                      getattr(args, "joint_convention", None))


def harmonics(text: str) -> list[int]:
    """--harmonics 1,2,3: transmission_error's harmonic orders."""
    try:
        h = [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected harmonic orders such as 1,2,3, not '{text}'") from None
    if not h or any(k < 1 for k in h) or len(set(h)) != len(h):
        raise argparse.ArgumentTypeError(f"harmonic orders must be distinct positive integers, not '{text}'")
    return h


def harmonics_option(sp: argparse.ArgumentParser, what: str) -> None:
    sp.add_argument("--harmonics", type=harmonics, default=list(ident.DEFAULT_HARMONICS), metavar="K1,K2",
                    help=f"harmonic orders of {what} (default 1,2)")


def effect_opts(sp: argparse.ArgumentParser, default: str, what: str) -> None:
    names = ", ".join(k.name for k in _core.effect_kinds() if k.domain == "serial")
    sp.add_argument("--effects", default=default,
                    help=f"{what}, comma separated: NAME (every joint where it applies) or NAME:J (joint J); "
                         f"joint_map:J:K a joint_map of order K (default {ident.DEFAULT_MAP_ORDER}); "
                         f"'none' for the geometry alone (default: {default}; known: {names})")
    harmonics_option(sp, "transmission_error")


def loss_opts(sp: argparse.ArgumentParser) -> None:
    """--loss, --loss-scale: one default for every fit (identify, diagnose, validate's refit)."""
    sp.add_argument("--loss", choices=["huber", "cauchy", "none"], default="huber", help="robust loss")
    sp.add_argument("--loss-scale", type=float, default=DEFAULT_LOSS_SCALE_MM,
                    help="where the robust loss bends (mm; default from the residuals' robust spread)")


def artifact_opt(sp: argparse.ArgumentParser) -> None:
    """--artifact: the known geometry between a probe campaign's stations; --probe: the ball's start."""
    sp.add_argument("--artifact", metavar="A.csv",
                    help="known distances and angles between the data's probe stations (columns a, b, distance_mm, "
                         "angle_deg; one of the last two per row): a length bar, a ball plate, a datum cube")
    sp.add_argument("--probe", metavar="X,Y,Z", help="the probe ball's nominal centre in the tool frame (mm): where "
                    "the fit of its offset starts (default: the tool frame's origin; a ballbar's pivots may start "
                    "on the wrong side of the ball without it)")


def probe_start(args: argparse.Namespace) -> Optional[list[list[float]]]:
    """--probe as the targets' start (one target), or None."""
    return [probe_offset(args)] if getattr(args, "probe", None) else None


def fit_opts(sp: argparse.ArgumentParser, noise: bool = True) -> None:
    """The fitting options of identify and diagnose: one group, one default each (kincal.calibration.fitting).
    ``noise``: the fits' noise is --noise (else --fit-noise: diagnose's --noise is where its steps stop)."""
    loss_opts(sp)
    sp.add_argument("--prior-model", metavar="JSON", help="centre the priors on this model's calibrated "
                    "geometry (e.g. last year's calibration; default: the starting model)")
    sp.add_argument("--prior-sd", metavar="KIND=SD,..", help="prior standard deviations over the defaults "
                    f"({', '.join(f'{k}={v:g}' for k, v in priors.DEFAULT_PRIOR_SD.items())}; also base_mm, "
                    "base_deg, target_mm, an effect's name); 'none': no priors (what the data cannot determine "
                    "is then refused)")
    sp.add_argument("--prior-scale", default="1", help="times every prior sd, or 'auto' (grouped cross-validation)")
    sp.add_argument("--gravity", choices=["auto", "masses", "fit"], default="auto", help="the compliances' "
                    "gravity torques: the model's masses, or mass moments identified (fit); auto: fit when it "
                    "has no masses")
    sp.add_argument("--max-iterations", type=int, default=100, metavar="N",
                    help="the cap of each Levenberg-Marquardt solve (default 100)")
    sp.add_argument("--tool-targets", metavar="CSV",
                    help="x,y,z of every target in the tool frame (designed or measured on a CMM, in target "
                         "order): places the tool frame (TCP), which reflectors alone cannot")
    sp.add_argument("--artifact-sd", type=float, metavar="MM", help="the uncertainty of the --artifact file's "
                    "lengths (mm; an angle's on a 1 m lever): they weigh the noise / it against the rows (default: "
                    "each as one coordinate of a row)")
    sp.add_argument("--noise" if noise else "--fit-noise", type=float, metavar="MM", dest="fit_noise",
                    help="the instrument's (or probe's) noise per coordinate, when known: the fits weigh their "
                    "priors and bend the robust loss with it (default: estimated from the residuals)")
    sp.add_argument("--orientation-weight", type=float, default=100.0, metavar="MM_PER_RAD",
                    help="with measured orientations (a,b,c): mm of position residual worth one rad (default "
                         "100: 0.02 mm against 0.011 deg of noise)")


def fit_options(args: argparse.Namespace, robot: _core.Robot) -> FitOptions:
    """The fitting options of identify and diagnose (one group of options, one default each)."""
    prior_model = load_robot(args.prior_model) if args.prior_model else None
    if prior_model is not None and prior_model.dof != robot.dof:
        raise ValueError(f"{args.prior_model}: {prior_model.dof} joints but the robot has {robot.dof}")
    if args.gravity == "masses" and not masses(robot):
        raise ValueError(f"--gravity masses: the model {args.robot} has no link masses (no inertial data); use "
                         "--gravity fit (or auto)")
    return FitOptions(loss=args.loss, loss_scale_mm=args.loss_scale or None,
                      prior_sd=priors.parse_prior_sd(args.prior_sd), prior_model=prior_model,
                      prior_scale=priors.parse_prior_scale(args.prior_scale), gravity=args.gravity,
                      orientation_weight=args.orientation_weight, max_iterations=args.max_iterations,
                      target_start=probe_start(args), noise_mm=getattr(args, "fit_noise", None),
                      artifact_sd_mm=args.artifact_sd)


def effects_arg(args: argparse.Namespace, robot: _core.Robot, data: MeasurementSet) -> Union[str, list[_core.Effect]]:
    """--effects: "auto" (identify's default) or a list (checked against the data's columns)."""
    if args.effects.strip() == "auto":
        return "auto"
    effects = ident.parse_effects(args.effects, robot, args.harmonics)
    check_data(effects, data.with_columns(source=args.data), robot)  # named by its file
    return effects


def tool_targets(path: Optional[str], data: MeasurementSet, data_path: str) -> Optional[FloatArray]:
    """--tool-targets: x,y,z of each target of the measurements in the tool frame, one row each
    (checked before any fit: an error names the file and both counts)."""
    if not path:
        return None
    known = _core.read_csv_columns(path, ["x", "y", "z"])
    n = int(np.max(data.target)) + 1
    if len(known) != n:
        raise ValueError(f"{path}: {len(known)} rows, but {data_path} measures {n} target(s) (one row of x,y,z per "
                         "target in the tool frame, in target order)")
    return known


def progress(label: str) -> Optional[Callable[[int, float], None]]:
    """A one-line progress report of a solver's iterations on stderr (quiet when not a terminal)."""
    if not sys.stderr.isatty():
        return None

    def report(iteration: int, cost: float) -> None:
        print(f"\r{label}: iteration {iteration}, cost {cost:.6g}   ", end="", file=sys.stderr, flush=True)
    return report


def step_progress(label: str) -> Optional[Callable[[int, int], None]]:
    """A one-line report of a loop's steps on stderr (quiet when not a terminal)."""
    if not sys.stderr.isatty():
        return None

    def report(step: int, steps: int) -> None:
        print(f"\r{label}: {step + 1} of {steps}   ", end="", file=sys.stderr, flush=True)
    return report


def say(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def probe_opts(sp: argparse.ArgumentParser, title: str) -> None:
    """A probe campaign's options (simulate --kind, plan --kind)."""
    probe = sp.add_argument_group(title)
    probe.add_argument("--kind", choices=["sphere", "plane", "distance"],
                       help="spheres in fixed nests, the faces of a block, or a ballbar at pivots")
    probe.add_argument("--stations", type=int, default=3, help="spheres or pivots; planes: the block's top, the "
                       "face towards the robot, the sideways ones, the plate it stands on (<= 5)")
    probe.add_argument("--touches", type=int, default=25, help="rows per station")
    probe.add_argument("--cone", type=float, default=35.0, metavar="DEG",
                       help="the probe's axis within this angle of its station's mean direction")
    probe.add_argument("--probe", default="0,0,150", metavar="X,Y,Z", help="the ball centre in the tool frame (mm)")
    probe.add_argument("--radius", type=float, default=3.0, help="the ball's radius (mm; planes)")
    probe.add_argument("--length", type=float, default=150.0, help="the ballbar's length (mm)")
    probe.add_argument("--block", type=float, default=400.0, help="the block's edge (mm; planes)")
    probe.add_argument("--artifact-out", metavar="A.csv",
                       help="the known distances and angles between the stations (default: OUT's name + -artifact.csv)")


def probe_offset(args: argparse.Namespace) -> list[float]:
    """--probe X,Y,Z (mm)."""
    try:
        probe = [float(v) for v in args.probe.split(",")]
    except ValueError:
        probe = []
    if len(probe) != 3 or not all(math.isfinite(v) for v in probe):
        raise ValueError(f"--probe {args.probe}: expected X,Y,Z (mm, the ball centre in the tool frame)")
    return probe


def artifact_out(args: argparse.Namespace) -> str:
    """--artifact-out, or OUT's name + -artifact.csv beside it."""
    return str(args.artifact_out or Path(args.out).with_name(Path(args.out).stem + "-artifact.csv"))
