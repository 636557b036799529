"""Identification of a serial robot from measurements: fitting options, priors, the effect choice, setups, the tool frame, simulation and campaign planning."""
