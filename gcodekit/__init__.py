"""gcodekit: read, emulate and analyse G-code and NC programs."""
