"""Emulate stage: LinuxCNC's lathe cycles G70 (finish) and G71/G72 (rough) as plain moves.

Behaviour mirrored: LinuxCNC 2.9 ``interp_g7x.cc`` (Debian 12 package
2.9.0~pre1, git 2023-02-08), whose output the golden cases record.

Points are complex numbers ``z + x*1j`` in program coordinates (X a
radius).  The profile is the chain of G0/G1/G2/G3 blocks of the ``Q``
subroutine (a :class:`~gcodekit.lathe_profile.LatheProfile`, read by the
preprocess stage), starting at the cycle point (the block's X/Z).  The cycle
mirrors and rotates the profile so that it always descends in X and Z
(``Contour.normalise``), works there, and maps every move back.

* G71 cuts passes parallel to Z, G72 (the profile turned 90 degrees)
  parallel to X; ``I`` apart, leaving ``D`` to the profile.  Each pass is
  fed in, then the tool escapes by ``R`` at 45 degrees and rapids back.
  G71.1/G72.1 skip the pockets (they only follow the profile out of them),
  G71.2/G72.2 cut only the pockets.
* G70 follows the profile ``P`` times at distances going from ``D`` down
  to ``E``.
* ``A`` on a profile block rounds the corner at its end point with that
  radius, ``C`` chamfers it.

The offset profile is built by LinuxCNC's stepwise method: every segment is
moved by at most half the shortest segment's length at a time, arcs fill
the gaps at convex corners and neighbours are re-intersected.
"""

from .cycle import LATHE_CYCLES, CycleBlock, LatheCycle, run_lathe_cycle
from .segments import TOLERANCE, LatheCycleError, Move

__all__ = ["LATHE_CYCLES", "CycleBlock", "LatheCycle", "LatheCycleError", "Move", "TOLERANCE", "run_lathe_cycle"]
