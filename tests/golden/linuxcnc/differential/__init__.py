"""Differential check of gcodekit against LinuxCNC's rs274 on random RS274NGC programs.

``generate`` writes seeded random programs, ``rs274`` runs the reference,
``compare`` judges one program motion by motion, ``shrink`` reduces a
disagreeing program to a small reproducer and ``run`` reports the agreement
rate and the clusters of differences (see README.md).
"""
