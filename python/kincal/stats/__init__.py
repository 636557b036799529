"""Statistics the calibration and the diagnosis share: grouped configurations, the F distribution, robust scores and the stepwise search engine."""
