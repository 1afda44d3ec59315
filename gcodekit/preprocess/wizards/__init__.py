"""Preprocess stage: GER wizards, named commands expanded to plain G-code.

GER (seeds/ger_manual.md, sections 2 and 4) lets a program call *wizards*:
a line that starts with a name of two or more letters, followed by
space-separated arguments (numbers, or strings in double quotes) that run
to the end of the line::

    G21
    Pocket 75.0 30.0 10.0      (a 75 x 30 mm pocket, 10 mm deep)

:class:`WizardStage` replaces each call by the lines its function returns;
every emitted line keeps the call's file and line number, so later
diagnostics and the ``line`` column point at the call.  Wizards are kept in
a :class:`WizardRegistry` keyed by name (case-insensitive); the module-level
:func:`register_wizard`, :func:`unregister_wizard`, :func:`wizard` and
:func:`wizards` use the default registry, which holds the built-ins:

``Pocket width height depth [stepdown] [stepover]``
    Rectangular pocket centred on X0 Y0, from the surface Z0 down to
    Z-depth: a zigzag along X, then one pass round the walls, per depth.
``CirclePocket diameter depth [stepdown] [stepover]``
    Round pocket centred on X0 Y0: concentric full circles (G3 with I/J).
``DrillGrid nx ny dx dy depth [peck]``
    ``nx`` by ``ny`` holes, the first at X0 Y0, spaced ``dx`` and ``dy``.
``BoltCircle count diameter depth [start_angle]``
    ``count`` holes on a circle centred on X0 Y0; angle in degrees from +X.
``Face width height depth [stepdown] [stepover]``
    Face the rectangle X0..width, Y0..height (lower-left corner at the
    origin, as GER advises setting the PRZ) down to Z-depth.

Lengths are in the program's units at the call (G20/G21, starting with the
flavor's); ``stepover`` is a length, at most the tool diameter.  Defaults,
all from the stage's ``settings`` (lengths in mm, feeds in mm/min, converted
to the current units): ``tool_diameter`` 6.35 (a 1/4 in end mill; or
``tools[T]`` for the tool selected by ``M6 Tn``), ``stepdown`` half the tool
diameter, ``stepover`` 0.4 tool diameters, ``feed`` 500, ``plunge_feed``
200, ``safe_z`` 5 (rapid height above Z0).  The built-ins emit only
G0/G1/G3 with X Y Z I J F, valid for GER and RS274NGC; they switch to G90
for their moves (and back to G91 if the program was incremental), plunge
straight down and end at ``safe_z``, in G0 mode.

The package holds the stage (:mod:`.stage`, with the reading and checking
of a call's arguments in :mod:`.arguments`), the registry
(:mod:`.registry`), what a wizard is given (:mod:`.context`) and the
built-ins (:mod:`.builtins`).

A wizard function is called as ``function(context, *arguments)`` with a
:class:`WizardContext` and the call's arguments in order (``float`` or
``str``; ``int`` when the parameter is annotated ``int``), and returns
lines of G-code (an iterable of str, read lazily up to the stage's
``max_lines``).  Emitted lines are not searched for further wizard calls.
Wrong argument counts or types, bad argument text and unknown wizards are
reported at the call's ``file:line:col``; a wizard that raises becomes a
diagnostic with its message (lenient) or a :class:`WizardError` (strict).
"""

from .builtins import bolt_circle, circle_pocket, drill_grid, face, pocket
from .context import DEFAULT_SETTINGS, MAX_LINES, WizardArgumentError, WizardContext
from .registry import (
    DEFAULT_REGISTRY,
    WizardRegistry,
    WizardWarning,
    register_wizard,
    unregister_wizard,
    wizard,
    wizards,
)
from .stage import WizardError, WizardStage, needs_wizards

__all__ = [
    "WizardStage",
    "WizardRegistry",
    "WizardContext",
    "WizardError",
    "WizardWarning",
    "WizardArgumentError",
    "register_wizard",
    "unregister_wizard",
    "wizards",
    "wizard",
    "needs_wizards",
    "DEFAULT_REGISTRY",
    "DEFAULT_SETTINGS",
    "MAX_LINES",
    "pocket",
    "circle_pocket",
    "drill_grid",
    "bolt_circle",
    "face",
]
