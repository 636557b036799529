"""`kincal diagnose --robot R` as a command: the diagnosis of serial.py, the final model identified on
all the data, and the folder it writes (report.html with its figures from serial_report.py,
diagnosis.json, model.json), whole or not at all; and the command's summary."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional, Union

from .. import _core
from .._core import Robot
from ..calibration import identify as ident
from ..io import strict_json
from .. import report
from ..stats import stepwise as engine
from .serial import diagnose, final_identification
from .serial_report import write_report

if TYPE_CHECKING:
    from .._core import MeasurementSet
    from ..typing_ import FloatArray


def run(robot: Robot, data: MeasurementSet, out: Union[str, Path], *, title: str,
        tool_targets: Optional[FloatArray] = None, progress: Optional[Callable[[str], None]] = None,
        **options: Any) -> tuple[dict[str, Any], ident.Identification]:
    """`kincal diagnose`: the diagnosis (``options``: those of diagnose()), the final model identified
    on all the data, and in the folder ``out`` report.html with its figures, diagnosis.json and
    model.json. Returns the diagnosis and the final identification."""
    say = progress or (lambda s: None)
    report.check_folder(out)  # before the work, not after it
    diag = diagnose(robot, data, progress=progress, **options)
    say("identifying the final model on all the data")
    model = final_identification(robot, data, diag, tool_targets)
    diag["final_model"]["file"] = "model.json"
    diag["final_model"]["parameters"] = [
        {"effect": e.name, "joint": e.joint or None, "label": e.label,
         "values": [v * sc for v, sc in zip(vals, e.file_scale)], "units": e.file_units}
        for e, vals in model.robot.effects]
    with report.staged_folder(out, owned=("step*.png", "residual_variables.png")) as folder:  # whole or nothing
        write_report(robot, data, diag, folder, title=title, model_file="model.json")
        _core.write_file_atomic(str(folder / "diagnosis.json"), strict_json.dumps(engine.contract_json(diag), indent=1) + "\n")
        _core.write_file_atomic(str(folder / "model.json"), model.model_json())
    return diag, model


def summary(diag: dict[str, Any], model: ident.Identification, out: Union[str, Path], seconds: float) -> str:
    """`kincal diagnose`'s summary of run()'s results: each named effect, the final verdict and the
    files written in ``out``."""
    folder = Path(out)
    lines = []
    for st in diag["steps"]:
        j = f" joint {st['joint']}" if st["joint"] else ""
        o = f" order {st['order']}" if st.get("order") else ""
        lines.append(f"{st['effect']}{j}{o}: cross-validated RMS {st['rms_before_mm'] * 1000:.1f} -> "
                     f"{st['rms_after_mm'] * 1000:.1f} um (F = {st['evidence']['F']:.3g})")
    lines.append(f"final cross-validated RMS {diag['final_rms_mm'] * 1000:.1f} um, {engine.noise_phrase(diag)}: "
                 f"{diag['verdict']} ({seconds:.1f} s); "
                 f"report: {folder / 'report.html'}; model ({' + '.join(['geometry'] + model.effect_labels())}): "
                 f"{folder / 'model.json'}")
    if diag.get("residual_summary"):
        lines.append(diag["residual_summary"])
    return "\n".join(lines)
