"""Files in and out: strict JSON, CSV text, URDF chains, public data sets."""
