"""The HTML pages and staged figures every report is written with (page.py; its names are this
package's)."""

from .page import check_folder, error_norm, esc, figure, page, staged_folder, table, write

__all__ = ["check_folder", "error_norm", "esc", "figure", "page", "staged_folder", "table", "write"]
