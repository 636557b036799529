"""Model discrepancy (`kincal diagnose`): find where the model and the measurements disagree, name
the missing effect, add it, refit, and show the gap shrink.

- kincal.stepwise (the engine): the greedy search, the F-test and the cross-validated scores, for every
  mechanism; kincal.effect_choice: the serial robot's candidates, refit and linearisation (shared with
  `identify --effects auto`, whose kept effects are the diagnosis's first steps);
- serial: the serial robot's diagnosis, the final model, the command's files;
- serial_report: the serial robot's figures and report.html.
The five-bar hidden robot's diagnosis (kincal.fivebar.diagnose) uses the same engine.
"""

from ..stepwise import Search, contract_json, cv_rms, score
from .serial import SerialProblem, Spec, candidates, diagnose, final_identification, run, step_effect, summary
from .serial_report import write_report

__all__ = ["Search", "contract_json", "cv_rms", "score", "SerialProblem", "Spec", "candidates", "diagnose",
           "final_identification", "run", "step_effect", "summary", "write_report"]
