"""Model discrepancy (`kincal diagnose`): find where the model and the measurements disagree, name
the missing effect, add it, refit, and show the gap shrink.

- kincal.stats.stepwise (the engine): the greedy search, the F-test and the cross-validated scores, for every
  mechanism; kincal.calibration.effect_choice: the serial robot's candidates, refit and linearisation (shared with
  `identify --effects auto`, whose kept effects are the diagnosis's first steps);
- serial: the serial robot's diagnosis and its final model; residual_vars: what the final model
  still misses, scored against every candidate variable;
- serial_report: the serial robot's figures and report.html;
- workflow: the command (the diagnosis, the final model, the files written whole or not at all).
The five-bar hidden robot's diagnosis (kincal.fivebar.diagnose) uses the same engine.
"""

from ..stats.stepwise import Search, contract_json, cv_rms, score
from .serial import SerialProblem, Spec, candidates, diagnose, final_identification, step_effect
from .serial_report import write_report
from .workflow import run, summary

__all__ = ["Search", "contract_json", "cv_rms", "score", "SerialProblem", "Spec", "candidates", "diagnose",
           "final_identification", "run", "step_effect", "summary", "write_report"]
