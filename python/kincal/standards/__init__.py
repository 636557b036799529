"""Standard accuracy figures: ISO 9283, ISO 230-2 and VDI/DGQ 3441 statistics, the ISO 9283 plan and their report."""
