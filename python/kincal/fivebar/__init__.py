"""The Kiper paper's five-bar mechanism controlled through its hidden robot: link-length synthesis,
the error-correction matrix and commands (hidden_robot), and the diagnosis of what the four lengths
miss (diagnosis). Their names are this package's."""

from .._core import ErrorMatrix, FiveBar
from .diagnosis import (LINKS, Diagnosis, diagnose, diagnosis_summary, effects_of, fit_with_effects, library,
                        predict, write_diagnosis)
from .hidden_robot import (COMMAND_TOLERANCE_DEG, METHODS, WORKSPACE, check_commanded_by, command,
                           error_map_figure, fit, grid_targets, largest_error, load_fit, load_matrix,
                           minimax_fit, model_of, points_csv, position_errors, read_table)

__all__ = ["ErrorMatrix", "FiveBar", "LINKS", "Diagnosis", "diagnose", "diagnosis_summary", "effects_of",
           "fit_with_effects", "library", "predict", "write_diagnosis", "COMMAND_TOLERANCE_DEG", "METHODS",
           "WORKSPACE", "check_commanded_by", "command", "error_map_figure", "fit", "grid_targets",
           "largest_error", "load_fit", "load_matrix", "minimax_fit", "model_of", "points_csv",
           "position_errors", "read_table"]
