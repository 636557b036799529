"""Programs and their analysis: pose and joint files, derivative analysis against the drives' limits."""
