"""Seeded random RS274NGC programs for the differential check against rs274.

:func:`generate` writes one program from one seed: 20-120 blocks mixing
units, distance modes (also for arc centres), planes, rapid and feed moves,
arcs by centre (IJK) and by radius (R) with helices and extra turns, work
systems with G10 L2/L20 (rotation included), the G92 family, tool changes
and tool length offsets (G43, G43.1 on some axes, G43.2, G49), canned
cycles (G73, G74, G81-G89 in all three planes, G98/G99, L repeats, blocks
that repeat the cycle with axis words alone), cutter compensation (G41/G42
by tool number, G41.1/G42.1 by diameter), G93/G95 feed modes, G28/G30/G53,
numbered and named parameters, expressions with functions, O-word
subroutines, if/while/do/repeat, dwell, spindle and coolant.  About one
program in eight carries one deliberate error that rs274 refuses.

The generator keeps a small model of the interpreter (units, modes, plane,
the program position while it knows it) so that its arcs are geometrically
valid; where it does not know the position it writes the end point as an
expression of LinuxCNC's ``#<_x>``-style parameters.  Every non-blank line
is unique (a repeated one gets a numbered comment), so rs274's error
message, which quotes the block, names exactly one line.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

#: Tools of the default tool table (``tooltables/tool.tbl``): diameter in inches.
TOOLS = {1: 0.125, 2: 0.0625, 3: 0.201}
#: Plane -> (first axis, second axis, normal axis) of its arcs and cycles, as rs274 orders them.
PLANE_AXES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}
LETTERS = "XYZ"
CENTRE_LETTERS = "IJK"
CYCLES = ("G81", "G82", "G83", "G73", "G85", "G86", "G89", "G84", "G74", "G87", "G88")
CYCLE_WEIGHTS = (6, 4, 4, 3, 4, 3, 4, 2, 2, 1, 1)


@dataclass(frozen=True)
class Program:
    """A generated program: its seed, text and the block kinds it uses."""

    seed: int
    text: str
    features: frozenset[str]


@dataclass
class _Model:
    """What the generator knows of the interpreter's state."""

    metric: bool = True
    incremental: bool = False
    arc_incremental: bool = True  # LinuxCNC starts in G91.1
    plane: int = 17
    pos: list = field(default_factory=lambda: [0.0, 0.0, 0.0])  # program X Y Z; None where not known
    feed: bool = False  # a non-zero feed rate in force (G94/G95)
    feed_mode: int = 94
    spindle: int = 0  # 0 stopped, 3 clockwise, 4 counterclockwise
    system: int = 1  # G54 = 1 .. G59.3 = 9
    cycle: str = ""  # the canned cycle in force
    motion: str = ""  # G0 or G1 in force (axis words alone repeat it)

    @property
    def u(self) -> float:
        """Program units per mm."""
        return 1.0 if self.metric else 1 / 25.4

    @property
    def digits(self) -> int:
        return 4 if self.metric else 5


def num(value: float, digits: int = 4) -> str:
    """A number as a G-code word value: fixed point, no trailing zeros.

    Examples
    --------
    >>> num(1.50), num(-0.00001), num(2.0)
    ('1.5', '0', '2')
    """
    text = f"{value:.{digits}f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


class _Writer:
    """Writes one program block by block, keeping :class:`_Model` up to date."""

    def __init__(self, seed: int):
        self.rng = random.Random(seed)
        self.m = _Model()
        self.lines: list[str] = []
        self.features: set[str] = set()
        self.labels = 0
        self.params: dict[str, float] = {}  # named parameters of the main program and their values
        self.subs: list[tuple[str, int]] = []  # (O-word name, argument count)

    # -- helpers ---------------------------------------------------------------

    def chance(self, p: float) -> bool:
        return self.rng.random() < p

    def length(self, lo: float, hi: float) -> float:
        """A random length in mm, in program units, rounded as written."""
        return round(self.rng.uniform(lo, hi) * self.m.u, self.m.digits)

    def n(self, value: float) -> str:
        return num(value, self.m.digits)

    def label(self) -> str:
        self.labels += 1
        return f"o<l{self.labels}>" if self.chance(0.7) else f"o{100 + self.labels}"

    def emit(self, *lines: str) -> None:
        self.lines.extend(lines)

    def expr(self, value: float) -> str:
        """A bracketed expression worth ``value`` (to 1e-6), now and then with functions or parameters."""
        r = self.rng
        kind = r.randrange(6)
        if kind == 0 and self.params:
            name, p = r.choice(sorted(self.params.items()))
            rest = value - p
            return f"[#<{name}> {'+' if rest >= 0 else '-'} {abs(rest):.6f}]"
        if kind == 1:
            return f"[sin[30] * {2 * value:.6f}]"
        if kind == 2 and value >= 0:
            return f"[sqrt[{value * value:.8f}]]"
        if kind == 3:
            return f"[{2 * value:.6f} / 2]"
        if kind == 4 and value >= 0:
            return f"[abs[-{value:.6f}]]"
        a = round(r.uniform(-20, 20), 3)
        rest = value - a
        return f"[{a} {'+' if rest >= 0 else '-'} {abs(rest):.6f}]"

    def value(self, value: float) -> str:
        """``value`` as a literal, or now and then as an expression."""
        return self.expr(value) if self.chance(0.12) else self.n(value)

    def feed_word(self, force: bool = False) -> str:
        """An F word when the mode needs one (or at random); empty otherwise."""
        m = self.m
        if m.feed_mode == 93:  # inverse time: every feed move has its own F
            return f"F{num(self.rng.uniform(5, 60), 2)}"
        if not force and m.feed and not self.chance(0.2):
            return ""
        m.feed = True
        if m.feed_mode == 95:
            return f"F{self.n(self.rng.uniform(0.05, 0.3) * m.u)}"
        return f"F{num(self.rng.uniform(50, 1500) * m.u, 2)}"

    def ensure_feed_per_minute(self) -> None:
        if self.m.feed_mode != 94:
            self.m.feed_mode = 94
            self.emit(f"G94 {self.feed_word(force=True)}")

    def ensure_absolute(self) -> None:
        if self.m.incremental:
            self.emit("G90")
            self.m.incremental = False

    def target_words(self, axes: list[int], box: tuple[float, float, float]) -> list[str]:
        """Words moving ``axes`` (absolute within +-box mm, or increments); tracks the position."""
        m, words = self.m, []
        for ax in axes:
            if m.incremental:
                delta = self.length(-box[ax] / 2, box[ax] / 2)
                words.append(LETTERS[ax] + self.value(delta))
                m.pos[ax] = None if m.pos[ax] is None else m.pos[ax] + delta
            else:
                value = self.length(-box[ax], box[ax]) if ax < 2 else self.length(-10, box[2])
                words.append(LETTERS[ax] + self.value(value))
                m.pos[ax] = value
        return words

    # -- blocks ----------------------------------------------------------------

    def move(self) -> None:
        r, m = self.rng, self.m
        code = r.choice(("G0", "G1", "G1"))
        axes = sorted(r.sample(range(3), r.choice((1, 2, 2, 3))))
        words = self.target_words(axes, (60, 60, 30))
        feed = self.feed_word() if code == "G1" else ""
        line = " ".join([code, *words, feed]).strip()
        if self.chance(0.05):
            line = line.lower()
        self.emit(f"N{10 * len(self.lines)} {line}" if self.chance(0.05) else line)
        m.motion, m.cycle = code, ""
        self.features.add("move")

    def modal_move(self) -> None:
        """Axis words alone: the G0/G1 in force moves again."""
        m = self.m
        if m.motion not in ("G0", "G1") or m.cycle or (m.motion == "G1" and m.feed_mode == 93):
            return self.move()
        axes = sorted(self.rng.sample(range(3), 2))
        self.emit(" ".join(self.target_words(axes, (60, 60, 30))))
        self.features.add("modal move")

    def arc(self, code: str | None = None, by_radius: bool | None = None) -> None:
        r, m = self.rng, self.m
        code = code or r.choice(("G2", "G3"))
        a, b, normal = PLANE_AXES[m.plane]
        radius = self.rng.uniform(2, 25) * m.u
        start_angle = r.uniform(0, 2 * math.pi)
        full = self.chance(0.08)
        sweep = 2 * math.pi if full else r.uniform(0.3, 6.0)
        by_radius = (not full and abs(sweep - math.pi) > 0.15 and self.chance(0.35)) if by_radius is None \
            else by_radius and not full
        end_angle = start_angle + (sweep if code == "G3" else -sweep)
        d = self.m.digits
        centre = {a: round(-radius * math.cos(start_angle), d), b: round(-radius * math.sin(start_angle), d)}
        end = {a: round(centre[a] + radius * math.cos(end_angle), d),
               b: round(centre[b] + radius * math.sin(end_angle), d)}
        if full:
            end = {a: 0.0, b: 0.0}
        start = list(m.pos)
        words = []
        for ax in (a, b):
            if full and self.chance(0.5):
                continue  # no end words: a full circle back to the start
            words.append(LETTERS[ax] + self.relative(ax, end[ax]))
        if self.chance(0.2):  # a helix
            rise = self.length(-5, 5)
            if m.incremental or m.pos[normal] is not None:
                words.append(LETTERS[normal] + self.relative(normal, rise))
        if by_radius:
            words.append("R" + self.n(radius if sweep <= math.pi else -radius))
            self.features.add("arc R")
        else:
            for ax in (a, b):
                if abs(centre[ax]) < 1e-4 and self.chance(0.5):
                    continue
                if m.arc_incremental:
                    words.append(CENTRE_LETTERS[ax] + self.n(centre[ax]))
                elif start[ax] is not None:
                    words.append(CENTRE_LETTERS[ax] + self.n(start[ax] + centre[ax]))
                else:
                    words.append(CENTRE_LETTERS[ax] + self.since_start(ax, centre[ax]))
            if self.chance(0.1):
                words.append("P2")
            self.features.add("arc IJK" + (" absolute" if not m.arc_incremental else ""))
        self.emit(" ".join([code, *words, self.feed_word()]).strip())
        m.motion, m.cycle = code, ""

    def relative(self, ax: int, delta: float) -> str:
        """The word value moving axis ``ax`` by ``delta`` from where it is (updates the position)."""
        m = self.m
        if m.incremental:
            m.pos[ax] = None if m.pos[ax] is None else m.pos[ax] + delta
            return self.n(delta)
        if m.pos[ax] is not None:
            m.pos[ax] = round(m.pos[ax] + delta, m.digits)
            return self.n(m.pos[ax])
        return self.since_start(ax, delta)

    def since_start(self, ax: int, delta: float) -> str:
        """An expression: the axis's position before the block plus ``delta``."""
        sign = "+" if delta >= 0 else "-"
        self.features.add("position parameters")
        return f"[#<_{LETTERS[ax].lower()}> {sign} {self.n(abs(delta))}]"

    def units(self) -> None:
        m = self.m
        metric = not m.metric if self.chance(0.8) else m.metric
        factor = (25.4 if metric else 1 / 25.4) if metric != m.metric else 1.0
        m.pos = [None if p is None else p * factor for p in m.pos]
        m.metric = metric
        self.emit("G21" if metric else "G20")
        self.features.add("units")

    def distance(self) -> None:
        m = self.m
        if self.chance(0.75):
            m.incremental = not m.incremental
            self.emit("G91" if m.incremental else "G90")
            self.features.add("G91" if m.incremental else "G90")
        else:
            m.arc_incremental = not m.arc_incremental
            self.emit("G91.1" if m.arc_incremental else "G90.1")
            self.features.add("G90.1/G91.1")

    def plane(self) -> None:
        m = self.m
        m.plane = self.rng.choice([p for p in (17, 18, 19) if p != m.plane])
        self.emit(f"G{m.plane}")
        self.features.add("planes")

    def work_system(self) -> None:
        r, m = self.rng, self.m
        kind = r.randrange(3)
        if kind == 0:
            m.system = r.randint(1, 9)
            self.emit(("G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3")[m.system - 1])
            m.pos = [None, None, None]
            self.features.add("G54-G59.3")
            return
        index = r.choice((0, m.system, r.randint(1, 9)))
        axes = sorted(r.sample(range(3), r.randint(1, 3)))
        words = [LETTERS[ax] + self.n(self.length(-40, 40)) for ax in axes]
        if kind == 1:
            if self.chance(0.4):
                words.append(f"R{num(r.uniform(-90, 90), 3)}")
                self.features.add("rotation")
            self.emit(" ".join([f"G10 L2 P{index}", *words]))
            self.features.add("G10 L2")
        else:
            self.emit(" ".join([f"G10 L20 P{index}", *words]))
            self.features.add("G10 L20")
        if index in (0, m.system):
            m.pos = [None, None, None]

    def axis_offset(self) -> None:
        r, m = self.rng, self.m
        kind = r.choice(("G92", "G92", "G92.1", "G92.2", "G92.3"))
        if kind == "G92":
            axes = sorted(r.sample(range(3), r.randint(1, 3)))
            words = []
            for ax in axes:
                value = self.length(-30, 30)
                words.append(LETTERS[ax] + self.n(value))
                m.pos[ax] = value
            self.emit(" ".join(["G92", *words]))
        else:
            self.emit(kind)
            m.pos = [None, None, None]
        self.features.add("G92 family")

    def tool(self) -> None:
        r, m = self.rng, self.m
        kind = r.randrange(6)
        if kind == 0:
            tool = r.choice(sorted(TOOLS))
            self.emit(f"T{tool} M6" + (" G43" if self.chance(0.5) else ""))
            m.spindle = 0  # rs274 stops the spindle for the change
            self.features.add("tool change")
        elif kind == 1:
            self.emit("G43" if self.chance(0.3) else f"G43 H{r.choice(sorted(TOOLS))}")
            self.features.add("G43")
        elif kind == 2:
            axes = r.choice(([2], [0], [0, 2], [2]))
            self.emit(" ".join(["G43.1", *(LETTERS[ax] + self.n(self.length(-10, 10)) for ax in axes)]))
            for ax in axes:
                m.pos[ax] = None
            self.features.add("G43.1")
            return
        elif kind == 3:
            self.emit(f"G43.2 H{r.choice(sorted(TOOLS))}")
            self.features.add("G43.2")
        elif kind == 4:
            self.emit("G49")
            self.features.add("G49")
        else:
            self.emit(f"T{r.choice(sorted(TOOLS))}")
            return
        m.pos = [None, None, None]

    def spindle(self, direction: int | None = None) -> None:
        m = self.m
        m.spindle = direction or self.rng.choice((3, 4))
        self.emit(f"M{m.spindle} S{self.rng.choice((500, 1000, 1800, 2400))}")

    def cycle(self, depth: int = 0) -> None:
        r, m = self.rng, self.m
        if depth == 0 and self.chance(0.3):
            self.plane()
        code = r.choices(CYCLES, CYCLE_WEIGHTS)[0]
        self.ensure_feed_per_minute()
        if code == "G84" and m.spindle != 3:
            self.spindle(3)
        elif code == "G74" and m.spindle != 4:
            self.spindle(4)
        elif code in ("G86", "G87", "G88") and not m.spindle:
            self.spindle()
        a, b, normal = PLANE_AXES[m.plane]
        words = [r.choice(("G98", "G99", "")), code]
        if m.incremental:
            level_r = self.length(-4, 6)
            bottom = -self.length(1, 15)
            for ax in (a, b):
                if self.chance(0.8):
                    words.append(LETTERS[ax] + self.n(self.length(-25, 25)))
        else:
            level_r = self.length(0, 10)
            bottom = level_r - self.length(1, 15)
            for ax in (a, b):
                if self.chance(0.85):
                    value = self.length(-50, 50)
                    words.append(LETTERS[ax] + self.value(value))
        words += [LETTERS[normal] + self.n(bottom), "R" + self.n(level_r)]
        if code in ("G83", "G73"):
            words.append("Q" + self.n(self.length(0.5, 5)))
        if code in ("G82", "G86", "G88", "G89") or (code in ("G84", "G74") and self.chance(0.3)):
            words.append(f"P{num(r.uniform(0.1, 1.5), 2)}")
        if code == "G87":
            words += [CENTRE_LETTERS[a] + self.n(self.length(1, 3)), CENTRE_LETTERS[b] + self.n(self.length(-3, 3)),
                      CENTRE_LETTERS[normal] + self.n(self.length(1, 4) if m.incremental else bottom + self.length(1, 4))]
        if self.chance(0.3) and code != "G74":  # rs274 2.9 takes no L for G74 (it does for G84)
            words.append(f"L{r.randint(2, 4)}")
            self.features.add("L repeats")
        words.append(self.feed_word())
        self.emit(" ".join(w for w in words if w))
        m.cycle, m.motion = code, ""
        self.features.add(code)
        self.features.add("cycles")
        for _ in range(r.choice((0, 1, 1, 2, 3))):  # the cycle again, at new places (axis words alone)
            again = []
            for ax in (a, b):
                if self.chance(0.8):
                    again.append(LETTERS[ax] + self.n(self.length(-25, 25) if m.incremental else self.length(-50, 50)))
            if not again:  # (an R alone would be a word no code uses)
                again.append(LETTERS[a] + self.n(self.length(1, 10)))
            if self.chance(0.15):
                again.append("R" + self.n(level_r + self.length(0, 3)))
            self.emit(" ".join(again))
            self.features.add("cycle repeated by axis words")
        m.pos = [None, None, None]
        choice = r.random()
        if choice < 0.5:
            self.emit("G80")
            m.cycle = ""
        elif choice < 0.65 and depth == 0:
            self.plane()
            self.cycle(depth + 1)

    def compensation(self) -> None:
        r, m = self.rng, self.m
        self.ensure_absolute()
        self.ensure_feed_per_minute()
        if m.plane != 17:
            self.emit("G17")
            m.plane = 17
        u, d = m.u, m.digits
        x0, y0 = self.length(-30, 30), self.length(-30, 30)
        w, h = self.length(10, 30), self.length(10, 30)
        corners = [(x0, y0), (x0 + w, y0), (x0 + w, y0 + h), (x0, y0 + h)]
        clockwise = self.chance(0.5)
        if clockwise:
            corners.reverse()
        start = (round(x0 - 12 * u, d), round(y0 - 12 * u, d))
        self.emit(f"G0 X{self.n(start[0])} Y{self.n(start[1])}" + (f" Z{self.n(self.length(0, 5))}" if self.chance(0.5)
                                                                   else ""))
        side = r.choice(("G41", "G42"))
        if self.chance(0.7):
            on = f"{side} D{r.choice(sorted(TOOLS))}"
        else:
            on = f"{side}.1 D{self.n(r.uniform(1, 5) * u)}"
            self.features.add("G41.1/G42.1")
        feed = self.feed_word(force=self.chance(0.3))
        if self.chance(0.5):
            self.emit(on, f"G1 X{self.n(corners[0][0])} Y{self.n(corners[0][1])} {feed}".strip())
        else:
            self.emit(f"{on} G1 X{self.n(corners[0][0])} Y{self.n(corners[0][1])} {feed}".strip())
        path = corners[1:] + corners[:1]
        arc_edge = r.randrange(4) if self.chance(0.6) else -1
        here = corners[0]
        for k, (x, y) in enumerate(path):
            if k == arc_edge:  # a half circle bulging outwards instead of the straight edge
                code = "G2" if clockwise else "G3"
                if self.chance(0.5):
                    half = math.hypot(x - here[0], y - here[1]) / 2
                    self.emit(f"{code} X{self.n(x)} Y{self.n(y)} R{self.n(half)}")
                else:
                    i, j = (x - here[0]) / 2, (y - here[1]) / 2
                    if not m.arc_incremental:  # G90.1: the centre itself
                        i, j = i + here[0], j + here[1]
                    self.emit(f"{code} X{self.n(x)} Y{self.n(y)} I{self.n(i)} J{self.n(j)}")
            else:
                self.emit(f"G1 X{self.n(x)} Y{self.n(y)}")
            if self.chance(0.15):
                self.emit(f"G1 Z{self.n(self.length(-3, 0))}")
            here = (x, y)
        end = (round(here[0] - 12 * u, d), round(here[1] - 15 * u, d))
        if self.chance(0.5):
            self.emit("G40", f"G0 X{self.n(end[0])} Y{self.n(end[1])}")
        else:
            self.emit(f"G40 G1 X{self.n(end[0])} Y{self.n(end[1])}")
        m.pos = [end[0], end[1], None]
        m.motion, m.cycle = "G1", ""
        self.features.add("cutter compensation")

    def parameters(self) -> None:
        r, m = self.rng, self.m
        name = f"p{len(self.params) + 1}" if self.chance(0.8) or not self.params else r.choice(sorted(self.params))
        global_ = self.chance(0.2)
        if global_:
            name = "_g" + name
        value = self.length(-40, 40)
        kind = r.randrange(4)
        if kind == 0:
            text = self.n(value)
        elif kind == 1:
            text = self.expr(value)
        elif kind == 2:
            a = round(r.uniform(1, 5), 2)
            text = f"[{self.n(value / a)} * {a}]"
            value = round(value / a, m.digits) * a
        else:
            tenths = r.randint(-300, 300)
            text = f"[round[{tenths}.3] / 10]"  # away from a tie: LinuxCNC and Python round alike
            value = tenths / 10
        self.emit(f"#<{name}> = {text}")
        self.params[name] = value
        if self.chance(0.3):
            self.emit(f"#{r.randint(1, 30)} = [{self.n(value)} + {r.randint(1, 9)}]")
        # use it
        axes = [r.choice((0, 1))]
        code = r.choice(("G0", "G1"))
        if m.incremental:
            word = f"{LETTERS[axes[0]]}[#<{name}> / 4]"
            m.pos[axes[0]] = None
        else:
            word = f"{LETTERS[axes[0]]}#<{name}>"
            m.pos[axes[0]] = value
        self.emit(" ".join([code, word, self.feed_word() if code == "G1" else ""]).strip())
        m.motion, m.cycle = code, ""
        self.features.add("parameters")

    def relative_moves(self, count: int) -> list[str]:
        """Feed moves in G91 that leave the modes as they found them (for loops and branches)."""
        lines = [] if self.m.incremental else ["G91"]
        for _ in range(count):
            ax = self.rng.sample(range(2), self.rng.choice((1, 2)))
            lines.append("G1 " + " ".join(f"{LETTERS[a]}{self.n(self.length(-8, 8))}" for a in sorted(ax)))
        if not self.m.incremental:
            lines.append("G90")
        return lines

    def control(self) -> None:
        r, m = self.rng, self.m
        self.ensure_feed_per_minute()
        if not m.feed:
            self.emit(f"G1 {self.feed_word(force=True)}")
        kind = r.randrange(4)
        label = self.label()
        if kind == 0:
            counter = f"#<i{self.labels}>"
            limit = r.randint(1, 4)
            body = self.relative_moves(r.randint(1, 2))
            self.emit(f"{counter} = 0", f"{label} while [{counter} lt {limit}]", *body)
            if self.chance(0.3):
                inner = self.label()
                self.emit(f"{inner} if [{counter} eq {limit - 1}]", f"{label} break", f"{inner} endif")
            self.emit(f"{counter} = [{counter} + 1]", f"{label} endwhile")
            self.features.add("while")
        elif kind == 1:
            self.emit(f"{label} repeat [{r.randint(1, 3)}]", *self.relative_moves(r.randint(1, 2)), f"{label} endrepeat")
            self.features.add("repeat")
        elif kind == 2:
            counter = f"#<j{self.labels}>"
            self.emit(f"{counter} = 0", f"{label} do", *self.relative_moves(1), f"{counter} = [{counter} + 1]",
                      f"{label} while [{counter} lt {r.randint(1, 3)}]")
            self.features.add("do-while")
        else:
            test = r.choice(("gt", "lt", "ge", "le", "eq", "ne"))
            operand = r.choice(["#<_x>", "#<_y>", "#<_z>", *(f"#<{p}>" for p in self.params)])
            self.emit(f"{label} if [{operand} {test} {self.n(self.length(-20, 20))}]", *self.relative_moves(1))
            if self.chance(0.4):
                self.emit(f"{label} elseif [{operand} gt 0]", *self.relative_moves(1))
            if self.chance(0.6):
                self.emit(f"{label} else", *self.relative_moves(1))
            self.emit(f"{label} endif")
            self.features.add("if")
        m.pos = [None, None, None]
        m.motion, m.cycle = "G1", ""

    def call(self) -> None:
        r, m = self.rng, self.m
        if not self.subs:
            return self.move()
        self.ensure_feed_per_minute()
        name, count = r.choice(self.subs)
        args = [f"[{self.n(self.length(3, 15))}]" for _ in range(count - 1)]
        args.append(f"[{num(r.uniform(100, 900) * m.u, 2)}]")
        self.emit(f"{name} call {' '.join(args)}")
        m.incremental, m.arc_incremental, m.plane, m.feed = False, True, 17, True
        m.pos = [None, None, None]
        m.motion, m.cycle = "G1", ""
        self.features.add("subroutine call")

    def define_subroutines(self) -> None:
        """O-word subroutines at the head of the program (rs274 needs them before their calls)."""
        r = self.rng
        for k in range(r.choice((0, 1, 1, 2))):
            name = f"o<s{k + 1}>" if self.chance(0.7) else f"o{900 + k}"
            body = ["#<f> = #3", "G17 G91 G91.1", "G1 X#1 F#<f>"]
            shape = r.randrange(3)
            if shape == 0:
                body += ["G3 X0 Y#2 I0 J[#2 / 2]", "G1 X[0 - #1]", "G1 Y[0 - #2]"]
            elif shape == 1:
                body += ["G1 Y#2", f"o<c{k}> if [#1 gt 8]", "G2 X[0 - #1] Y0 R[#1 / 2]", f"o<c{k}> else",
                         "G1 X[0 - #1]", f"o<c{k}> endif", "G1 Y[0 - #2]"]
            else:
                body += ["#<k> = 0", f"o<w{k}> while [#<k> lt 2]", "G1 Y[#2 / 2]", "#<k> = [#<k> + 1]",
                         f"o<w{k}> endwhile", "G1 X[0 - #1] Y[0 - #2]"]
            if self.chance(0.3):
                body[3:3] = [f"o<r{k}> if [#1 lt 4]", "G90", f"{name} return", f"o<r{k}> endif"]
            body.append("G90")
            self.emit(f"{name} sub", *("  " + line for line in body), f"{name} endsub")
            self.subs.append((name, 3))
            self.features.add("subroutines")

    def feed_modes(self) -> None:
        r, m = self.rng, self.m
        if m.feed_mode != 94:
            return self.ensure_feed_per_minute()
        if self.chance(0.5):
            self.emit("G93")
            m.feed_mode = 93
            self.features.add("G93")
        else:
            if not m.spindle:
                self.spindle()
            self.emit("G95")
            m.feed_mode, m.feed = 95, False
            self.features.add("G95")
        for _ in range(r.randint(1, 3)):
            self.arc() if self.chance(0.3) else self.move()
        m.feed_mode = 94
        self.emit(f"G94 {self.feed_word(force=True)}")

    def home(self) -> None:
        r, m = self.rng, self.m
        kind = r.randrange(4)
        if kind == 0:
            self.emit(r.choice(("G28.1", "G30.1")))
            return
        if kind == 3 and not m.incremental:
            axes = sorted(r.sample(range(3), r.randint(1, 3)))
            self.emit(" ".join([f"G53 {r.choice(('G0', 'G1'))}",
                                *(LETTERS[ax] + self.n(self.length(-40, 40)) for ax in axes),
                                self.feed_word(force=True)]).strip())
            m.motion, m.cycle = "", ""
            self.features.add("G53")
        else:
            code = r.choice(("G28", "G30"))
            axes = sorted(r.sample(range(3), r.randint(0, 2)))
            words = [LETTERS[ax] + self.n(self.length(-20, 20)) for ax in axes]
            self.emit(" ".join([code, *words]))
            self.features.add("G28/G30")
        m.pos = [None, None, None]

    def misc(self) -> None:
        r = self.rng
        kind = r.randrange(9)
        if kind == 0:
            self.emit(f"G4 P{num(r.uniform(0.1, 1.0), 2)}")
        elif kind == 1:
            self.spindle()
        elif kind == 2:
            self.emit("M5")
            self.m.spindle = 0
        elif kind == 3:
            self.emit(r.choice(("M7", "M8", "M9")))
        elif kind == 4:
            self.emit(r.choice(("G61", "G61.1", "G64", "G64 P0.01")))
        elif kind == 5:
            self.emit(f"(a comment {len(self.lines)})")
        elif kind == 6:
            self.emit(f"; a semicolon comment {len(self.lines)}")
        elif kind == 7:
            self.emit(f"(msg, step {len(self.lines)})")
        else:
            self.emit("")

    # -- deliberate errors -----------------------------------------------------

    def error(self) -> None:
        r, m = self.rng, self.m
        kind = r.randrange(16)
        self.features.add("deliberate error")
        a, b, _ = PLANE_AXES[m.plane]
        if kind == 0:
            self.ensure_feed_per_minute()
            self.emit(f"G2 {LETTERS[a]}{self.n(self.length(1, 9))} {LETTERS[b]}{self.n(self.length(1, 9))} "
                      f"{self.feed_word(force=True)}")
        elif kind == 1:
            self.ensure_absolute()
            self.ensure_feed_per_minute()
            self.emit(f"G3 {LETTERS[a]}{self.n(self.length(60, 80))} R{self.n(self.length(1, 3))} "
                      f"{self.feed_word(force=True)}")
        elif kind == 2:
            self.emit("G93", f"G1 X{self.n(self.length(1, 9))} F20", "G94", f"G1 Y{self.n(self.length(1, 9))}")
            m.feed_mode = 94
        elif kind == 3:
            self.ensure_feed_per_minute()
            self.emit(f"G83 {LETTERS[PLANE_AXES[m.plane][2]]}{self.n(-self.length(5, 9))} R{self.n(self.length(1, 3))} "
                      f"Q{self.n(self.length(1, 2))} {self.feed_word(force=True)}", "G80",
                      f"G83 {LETTERS[PLANE_AXES[m.plane][2]]}{self.n(-self.length(5, 9))} R{self.n(self.length(1, 3))}")
        elif kind == 4:
            self.ensure_absolute()
            self.ensure_feed_per_minute()
            self.emit(f"G81 {LETTERS[PLANE_AXES[m.plane][2]]}{self.n(self.length(5, 9))} "
                      f"R{self.n(self.length(1, 3))} {self.feed_word(force=True)}")
        elif kind == 5:
            self.ensure_feed_per_minute()
            self.emit(f"T{r.choice(sorted(TOOLS))} M6", f"G86 {LETTERS[PLANE_AXES[m.plane][2]]}{self.n(-self.length(5, 9))} "
                      f"R{self.n(self.length(1, 3))} P0.5 {self.feed_word(force=True)}")
        elif kind == 6:
            self.ensure_feed_per_minute()
            self.spindle()
            self.emit(f"G80 G86 {LETTERS[PLANE_AXES[m.plane][2]]}{self.n(-self.length(5, 9))} "
                      f"R{self.n(self.length(1, 3))} {self.feed_word(force=True)}")
        elif kind == 7:
            self.ensure_feed_per_minute()
            self.emit("G18", f"G2 X{self.n(self.length(1, 5))} Z{self.n(self.length(1, 5))} "
                      f"I{self.n(self.length(1, 5))} J{self.n(self.length(1, 5))} {self.feed_word(force=True)}")
            m.plane = 18
        elif kind == 8:
            self.emit(f"G0 X#<nosuch{len(self.lines)}>")
        elif kind == 9:
            self.emit(f"#<d{len(self.lines)}> = [{r.randint(1, 5)} / [2 - 2]]")
        elif kind == 10:
            self.emit(f"G10 L2 P{r.choice((10, 12, -1))} X0")
        elif kind == 11:
            self.emit(f"G0 G1 X{self.n(self.length(1, 9))}")
        elif kind == 12:
            self.emit(f"T{r.choice((7, 12, 40))} M6")
        elif kind == 13:
            self.emit(f"o<nosub{len(self.lines)}> call")
        elif kind == 14:
            self.ensure_absolute()
            self.ensure_feed_per_minute()
            self.emit(f"G2 X0 Y0 R{self.n(self.length(2, 5))} {self.feed_word(force=True)}", "G2 R4")
        else:
            self.emit(f"G0 X{self.n(self.length(1, 9))} I{self.n(self.length(1, 9))}")
        m.pos = [None, None, None]

    # -- the program -----------------------------------------------------------

    BLOCKS = (("move", 20), ("modal_move", 3), ("arc", 12), ("units", 3), ("distance", 5), ("plane", 4),
              ("work_system", 4), ("axis_offset", 3), ("tool", 4), ("cycle", 12), ("compensation", 5),
              ("parameters", 4), ("control", 4), ("call", 4), ("misc", 5), ("feed_modes", 2), ("home", 2))

    def program(self, seed: int) -> Program:
        r = self.rng
        blocks = r.randint(20, 120)
        percent = self.chance(0.1)
        if percent:
            self.emit("%")
        self.define_subroutines()
        preamble = r.choice(("G21 G17 G90 G94", "G21 G90", "G20", "G17 G21 G40 G49 G80 G90", ""))
        if preamble:
            self.emit(preamble)
            self.m.metric = "G20" not in preamble
        error_at = r.randrange(blocks) if self.chance(0.12) else -1
        names, weights = zip(*self.BLOCKS)
        start = len(self.lines)
        while len(self.lines) - start < blocks:
            if error_at >= 0 and len(self.lines) - start >= error_at:
                self.error()
                error_at = -1
                continue
            getattr(self, r.choices(names, weights)[0])()
        self.emit(r.choice(("M2", "M30", "M2")))
        if percent:
            self.emit("%")
        return Program(seed, "\n".join(unique_lines(self.lines)) + "\n", frozenset(self.features))


def unique_lines(lines: list[str]) -> list[str]:
    """Give a repeated non-blank line a numbered comment so that every block text names one line.

    Examples
    --------
    >>> unique_lines(["G90", "G0 X1", "G90", "", ""])
    ['G90', 'G0 X1', 'G90 (2)', '', '']
    """
    seen: dict[str, int] = {}
    out = []
    for line in lines:
        key = " ".join(line.split()).lower()
        if key and key != "%":
            seen[key] = seen.get(key, 0) + 1
            if seen[key] > 1:
                line = f"{line} ({seen[key]})"
        out.append(line)
    return out


def generate(seed: int) -> Program:
    """The random program of ``seed`` (the same text on every run and platform).

    Examples
    --------
    >>> p = generate(7)
    >>> p.text == generate(7).text, p.text.rstrip().splitlines()[-1] in ("M2", "M30", "%")
    (True, True)
    """
    return _Writer(seed).program(seed)
