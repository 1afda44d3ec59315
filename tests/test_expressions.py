"""Preprocess stage: the RS274NGC expression evaluator against hand-computed values.

Expected values follow LinuxCNC 2.9 (``interp_read.cc``, ``interp_execute.cc``):
left-associative operators in five precedence levels, degrees, a sign that
belongs to its value, and errors for every undefined result.
"""

import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gcodekit.errors import GcodeError, GcodeExpressionError, GcodeLimitError
from gcodekit.preprocess import ParameterStore, evaluate, parse
from gcodekit.preprocess import expressions


@pytest.mark.parametrize(
    "text, expected",
    [
        # numbers
        ("1", 1.0), ("-1.5", -1.5), (".5", 0.5), ("1.", 1.0), ("+2", 2.0), ("007", 7.0),
        # each binary operator
        ("[2 ** 3]", 8.0), ("[4 ** 0.5]", 2.0), ("[-8 ** 2]", 64.0), ("[-2 ** -1]", -0.5),
        ("[6 * 7]", 42.0), ("[7 / 2]", 3.5),
        ("[7 MOD 3]", 1.0), ("[-7 MOD 3]", 2.0), ("[7 MOD -3]", 1.0), ("[-7.5 MOD 2]", 0.5),
        ("[1 + 2]", 3.0), ("[1 - 2]", -1.0),
        ("[1 EQ 1]", 1.0), ("[1 EQ 1.00005]", 1.0), ("[1 EQ 1.001]", 0.0),
        ("[1 NE 1.00005]", 0.0), ("[1 NE 2]", 1.0),
        ("[2 GT 1]", 1.0), ("[1 GT 1]", 0.0), ("[1.00005 GT 1]", 1.0),
        # EQ/NE have rs274's 0.0001 tolerance, GE/LE do not (both checked in rs274 2.9)
        ("[1 GE 1.00005]", 0.0), ("[1 GE 1]", 1.0), ("[1 GE 2]", 0.0),
        ("[1 LT 2]", 1.0), ("[1 LT 1]", 0.0), ("[1 LE 0.99995]", 0.0), ("[1 LE 1]", 1.0), ("[2 LE 1]", 0.0),
        ("[1 AND 2]", 1.0), ("[1 AND 0]", 0.0), ("[0 OR 0]", 0.0), ("[0 OR -3]", 1.0),
        ("[1 XOR 1]", 0.0), ("[1 XOR 0]", 1.0), ("[0 XOR 0]", 0.0),
        # precedence: ** then * / MOD then + - then relational then logical
        ("[2 + 3 * 4 ** 2]", 50.0),
        ("[2 - 3 * 4 / 5]", -0.4),
        ("[9+8*7/6+5-4*3**2+1]", 9 + 8 * 7 / 6 + 5 - 4 * 9 + 1),
        ("[1 + 2 EQ 3]", 1.0),
        ("[3 EQ 1 + 2]", 1.0),
        ("[1 LT 2 AND 3 GT 4]", 0.0),
        ("[0 AND 0 OR 1]", 1.0),  # same level, left to right: [0 AND 0] OR 1
        ("[1 OR 0 AND 0]", 0.0),  # [1 OR 0] AND 0
        ("[10 MOD 4 * 2]", 4.0),
        ("[2 * 10 MOD 4]", 0.0),
        # left associativity
        ("[8 - 2 - 1]", 5.0), ("[8 / 2 / 2]", 2.0), ("[2 ** 3 ** 2]", 64.0),
        # the sign belongs to the value: [-2 ** 2] is [[-2] ** 2]
        ("[-2 ** 2]", 4.0), ("[0 - 2 ** 2]", -4.0), ("[1 - -1]", 2.0), ("[2 * -3]", -6.0),
        ("--1", 1.0), ("-[1 + 2]", -3.0), ("+-1", -1.0),
        # functions, degrees
        ("ABS[-3]", 3.0), ("ABS[3]", 3.0),
        ("ACOS[0]", 90.0), ("ACOS[1]", 0.0), ("ASIN[1]", 90.0), ("ASIN[-1]", -90.0),
        ("COS[0]", 1.0), ("COS[180]", -1.0), ("SIN[90]", 1.0), ("SIN[-90]", -1.0),
        ("TAN[45]", 1.0 - 1.1102230246251565e-16),
        ("EXP[0]", 1.0), ("EXP[1]", math.e), ("LN[1]", 0.0), ("LN[EXP[2]]", 2.0),
        ("SQRT[16]", 4.0), ("SQRT[0]", 0.0),
        ("FIX[2.5]", 2.0), ("FIX[-2.5]", -3.0), ("FUP[2.5]", 3.0), ("FUP[-2.5]", -2.0),
        # a zero keeps its sign, as in C, and ATAN tells them apart
        ("ATAN[0]/[FUP[-0.5]]", 180.0), ("ATAN[0]/[-3 MOD 1]", 180.0), ("ATAN[0]/[ABS[-0]]", 180.0),
        ("ATAN[0]/[FIX[0.5]]", 0.0),
        ("ROUND[2.5]", 3.0), ("ROUND[-2.5]", -3.0), ("ROUND[2.4999]", 2.0), ("ROUND[-0.4]", 0.0),
        ("ATAN[1]/[1]", 45.0), ("ATAN[1]/[-1]", 135.0), ("ATAN[-1]/[-1]", -135.0),
        ("ATAN[0]/[-1]", 180.0), ("ATAN[1]/[0]", 90.0),
        # keywords are case-insensitive, whitespace is ignored everywhere
        ("[7 mod 3]", 1.0), ("sqrt[16]", 4.0), ("AtAn[1]/[1]", 45.0), ("[1 0 + 2]", 12.0),
        ("[ 1  m o d  2 ]", 1.0), ("S I N [ 9 0 ]", 1.0), ("[2andsin[30]]", 1.0),
        ("[[[1]]]", 1.0),
    ],
)
def test_values(text, expected):
    assert evaluate(text) == pytest.approx(expected, rel=1e-15, abs=1e-15)


def test_named_and_numbered_parameters():
    store = ParameterStore()
    store.set(1, 3.0)
    store.set(3, 4.5)
    store.set("Feed Rate", 100.0)
    store.set("_global", -1.0)
    assert evaluate("#1", store) == 3.0
    assert evaluate("##1", store) == 4.5  # #[#1] = #3
    assert evaluate("#[#1]", store) == 4.5
    assert evaluate("#[1 + 2]", store) == 4.5
    assert evaluate("#2.99999", store) == 4.5  # within 0.0001 of 3, as LinuxCNC
    assert evaluate("#5601", store) == 0.0  # unset numbered parameters read 0
    assert evaluate("#<feedrate>", store) == 100.0
    assert evaluate("#< F E E D  rate >", store) == 100.0
    assert evaluate("#<_GLOBAL>", store) == -1.0
    assert evaluate("[#1 * #<feedrate> + #<_global>]", store) == 299.0
    assert evaluate("-#1", store) == -3.0
    assert evaluate("EXISTS[#<feedrate>]", store) == 1.0
    assert evaluate("EXISTS[#<nothing>]", store) == 0.0
    assert evaluate("EXISTS[#5601]", store) == 1.0
    assert evaluate("EXISTS[#5602]", store) == 0.0


def test_parsed_tree_is_reusable():
    node = parse("[#1 * 2 + #<x>]")
    store = ParameterStore()
    store.set("x", 1.0)
    assert expressions.evaluate(node, store) == 1.0
    store.set(1, 10.0)
    assert expressions.evaluate(node, store) == 21.0


def test_system_parameters_are_read_only():
    store = ParameterStore(system=lambda key: 12.5 if key in (5420, "_x") else None)
    assert evaluate("#5420", store) == 12.5
    assert evaluate("[#<_X> + 1]", store) == 13.5
    assert store.read_only(5420) and not store.read_only(5421)
    with pytest.raises(GcodeExpressionError, match="read-only"):
        store.set(5420, 1.0)
    with pytest.raises(GcodeExpressionError, match="read-only"):
        store.set("_x", 1.0)


@pytest.mark.parametrize(
    "text, column, message",
    [
        ("[1 + 2 / 0]", 8, "division by zero"),
        ("[1 MOD 0]", 4, "MOD by zero"),
        ("[-8 ** 0.5]", 5, "non-integer power"),
        ("[0 ** -1]", 4, "negative power"),
        ("[1 + SQRT[-1]]", 6, "SQRT"),
        ("LN[0]", 1, "LN"),
        ("[2 * LN[-1]]", 6, "LN"),
        ("ACOS[1.5]", 1, "ACOS"),
        ("ASIN[-2]", 1, "ASIN"),
        ("[1 + FOO[2]]", 6, "unknown function 'FOO'"),
        ("SINE[1]", 1, "SINE"),
        ("[1 FOO 2]", 4, "unknown operator 'FOO'"),
        ("[1 SIN 2]", 4, "function, not an operator"),
        ("[1e5]", 3, "exponent"),
        ("[1 + 2", 1, "unclosed"),
        ("[1 + [2]", 1, "unclosed"),
        ("[]", 2, "value"),
        ("[1 +]", 5, "value"),
        ("", 1, "missing"),
        ("1.2.3", 1, "bad number"),
        (".", 1, "bad number"),
        ("SIN 30", 5, "'['"),
        ("ATAN[1]", 8, "ATAN[y]/[x]"),
        ("ATAN[1]/2", 8, "ATAN[y]/[x]"),
        ("EXISTS[1]", 8, "EXISTS"),
        ("#<undefined>", 1, "#<undefined> is not defined"),
        ("[1 + #<oops>]", 6, "not defined"),
        ("#<unclosed", 1, "'>'"),
        ("#<>", 1, "empty name"),
        ("#0", 1, "outside 1 .. 5601"),
        ("#5602", 1, "outside 1 .. 5601"),
        ("#-1", 1, "outside"),
        ("#1.5", 1, "not an integer"),
        ("[10 ** 400]", 5, "infinity"),
        ("EXP[1000]", 1, "infinity"),
        ("1" * 400, 1, "too large"),
        ("[1] 2", 5, "unexpected text"),
        ("[1 ! 2]", 4, "operator"),
    ],
)
def test_errors_name_the_column(text, column, message):
    with pytest.raises(GcodeExpressionError, match=re.escape(message)) as info:
        evaluate(text)
    assert not isinstance(info.value, GcodeLimitError)
    assert info.value.diagnostic.column == column
    assert info.value.diagnostic.text == text


def test_nesting_depth_limit():
    depth = expressions.MAX_DEPTH
    ok = "[" * (depth - 1) + "1" + "]" * (depth - 1)
    assert evaluate(ok) == 1.0
    too_deep = ["[" * depth + "1" + "]" * depth, "-" * 100 + "1", "#" * 100 + "1", "ABS[" * 80 + "1" + "]" * 80]
    for text in too_deep:
        with pytest.raises(GcodeLimitError, match="nested deeper"):
            evaluate(text)


def test_deep_nesting_is_a_limit_not_a_recursion_error():
    text = "[" * 10_000 + "1" + "]" * 10_000
    with pytest.raises(GcodeLimitError):
        evaluate(text)
    with pytest.raises(GcodeLimitError, match="nested deeper"):
        evaluate("[" * 4000 + "1" + "]" * 4000)


def test_length_limit():
    with pytest.raises(GcodeLimitError, match="longer than"):
        evaluate("[" + "+".join(["1"] * expressions.MAX_LENGTH) + "]")


def test_long_and_deep_expressions_need_no_recursion():
    # 4000 operands make a left-deep tree; every precedence level at every
    # depth is the worst case for a recursive evaluator.
    assert evaluate("[" + "+".join(["1"] * 4000) + "]") == 4000.0
    levels = 60
    worst = "[1 OR 1 EQ 1 + 1 * 1 ** " * levels + "1" + "]" * levels
    assert evaluate(worst) == 1.0


# --- Hypothesis: random trees against an independent reference -----------

PREC = {"**": 5, "*": 4, "/": 4, "MOD": 4, "+": 3, "-": 3,
        "EQ": 2, "NE": 2, "GT": 2, "GE": 2, "LT": 2, "LE": 2, "AND": 1, "OR": 1, "XOR": 1}
UNARY = ["ABS", "ACOS", "ASIN", "COS", "EXP", "FIX", "FUP", "LN", "ROUND", "SIN", "SQRT", "TAN"]
NUMBERED = {1: 2.5, 2: -3.0, 3: 0.0, 4: 10.0, 5: 0.5}
NAMED = {"_g": 7.0, "loc": -1.25}


class Undefined(Exception):
    """The reference finds no value: the evaluator must raise."""


def _number():
    ints = st.integers(0, 2000)
    return st.one_of(
        ints.map(lambda n: (str(n), float(n))),
        st.tuples(ints, st.integers(0, 999)).map(lambda t: f"{t[0]}.{t[1]:03d}").map(lambda s: (s, float(s))),
        st.integers(0, 999).map(lambda n: (f".{n:03d}", float(f".{n:03d}"))),
        ints.map(lambda n: (f"{n}.", float(n))),
    ).map(lambda nv: ("num", nv[0], nv[1]))


def _leaf():
    return st.one_of(
        _number(),
        st.sampled_from(sorted(NUMBERED)).map(lambda n: ("param", n)),
        st.sampled_from(["_g", "loc", "_G", "L o C"]).map(lambda n: ("named", n)),
    )


def _extend(children):
    return st.one_of(
        st.tuples(st.just("bin"), st.sampled_from(sorted(PREC)), children, children, st.booleans()),
        st.tuples(st.just("neg"), children),
        st.tuples(st.just("fn"), st.sampled_from(UNARY), children),
        st.tuples(st.just("atan"), children, children),
    )


trees = st.recursive(_leaf(), _extend, max_leaves=12)


def render(node, parent=None, right=False):
    """Text for a tree, with the brackets precedence needs (plus random extras)."""
    kind = node[0]
    if kind == "num":
        return node[1]
    if kind == "param":
        return f"#{node[1]}"
    if kind == "named":
        return f"#<{node[1]}>"
    if kind == "neg":
        inner = node[1]
        text = render(inner)
        return "-" + (f"[{text}]" if inner[0] == "bin" else text)
    if kind == "fn":
        return f"{node[1]}[{render(node[2])}]"
    if kind == "atan":
        return f"ATAN[{render(node[1])}]/[{render(node[2])}]"
    _, op, left, rgt, extra = node
    text = f"{render(left, op)} {op} {render(rgt, op, True)}"
    needed = parent is None or PREC[op] < PREC[parent] or (right and PREC[op] == PREC[parent])
    return f"[{text}]" if needed or extra else text


def reference(node):
    """Value of a tree, computed from the LinuxCNC rules without the evaluator."""
    kind = node[0]
    if kind == "num":
        return node[2]
    if kind == "param":
        return NUMBERED[node[1]]
    if kind == "named":
        return NAMED[node[1].replace(" ", "").lower()]
    if kind == "neg":
        return -reference(node[1])
    if kind == "atan":
        return check(math.atan2(reference(node[1]), reference(node[2])) * 180.0 / math.pi)
    if kind == "fn":
        return check(unary(node[1], reference(node[2])))
    a, b = reference(node[2]), reference(node[3])
    return check(binary(node[1], a, b))


def check(value):
    if not math.isfinite(value):
        raise Undefined
    return value


def unary(name, x):
    # Degrees as LinuxCNC converts them: (x * pi) / 180.
    rad = x * math.pi / 180.0
    if name in ("ACOS", "ASIN") and abs(x) > 1:
        raise Undefined
    if (name == "SQRT" and x < 0) or (name == "LN" and x <= 0):
        raise Undefined
    try:
        return {
            "ABS": lambda: x if x >= 0 else -x, "ACOS": lambda: math.acos(x) * 180.0 / math.pi,
            "ASIN": lambda: math.asin(x) * 180.0 / math.pi, "COS": lambda: math.cos(rad),
            "EXP": lambda: math.exp(x), "FIX": lambda: float(np.floor(x)),
            "FUP": lambda: float(np.ceil(x)), "LN": lambda: math.log(x),
            "ROUND": lambda: float(math.floor(x + 0.5) if x >= 0 else math.ceil(x - 0.5)),
            "SIN": lambda: math.sin(rad), "SQRT": lambda: math.sqrt(x), "TAN": lambda: math.tan(rad),
        }[name]()
    except OverflowError:
        raise Undefined from None


def modulo(a, b):
    """LinuxCNC: C fmod (a zero result keeps a's sign), then made non-negative."""
    r = float(np.fmod(a, b))
    return r + abs(b) if r < 0 else r


def binary(op, a, b):
    if op in ("/", "MOD") and b == 0:
        raise Undefined
    if op == "**" and ((a < 0 and b != int(b)) or (a == 0 and b < 0)):
        raise Undefined
    try:
        result = {
            "**": lambda: a ** b, "*": lambda: a * b, "/": lambda: a / b,
            "MOD": lambda: modulo(a, b), "+": lambda: a + b, "-": lambda: a - b,
        }[op]()
    except KeyError:
        pass
    except OverflowError:
        raise Undefined from None
    else:
        return result
    near = abs(a - b) < 0.0001
    truth = {
        "EQ": near, "NE": not near, "GT": a > b, "GE": a >= b, "LT": a < b, "LE": a <= b,
        "AND": a != 0 and b != 0, "OR": a != 0 or b != 0, "XOR": (a != 0) != (b != 0),
    }[op]
    return 1.0 if truth else 0.0


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees, lower=st.booleans(), spaces=st.booleans())
def test_random_trees_match_reference(tree, lower, spaces):
    text = render(tree)
    if lower:
        text = text.lower()
    if not spaces:
        text = text.replace(" ", "")
    store = ParameterStore()
    for n, v in NUMBERED.items():
        store.set(n, v)
    for name, v in NAMED.items():
        store.set(name, v)
    try:
        expected = reference(tree)
    except Undefined:
        with pytest.raises(GcodeExpressionError):
            evaluate(text, store)
        return
    got = evaluate(text, store)
    assert math.isclose(got, expected, rel_tol=1e-12, abs_tol=1e-12), text


# --- Hypothesis: arbitrary text only ever raises gcodekit errors ----------

TOKENS = ["[", "]", "#", "<", ">", "#<a>", "#<_b>", "1", "0", ".5", "2.", "-", "+", "**", "*",
          "/", "MOD", "EQ", "AND", "XOR", "SIN", "ATAN", "EXISTS", "/[", " ", "=", "(", ")",
          ";", "e", "x", "#1", "##", "5602", "ROUND", "LN", "SQRT", "ACOS", "\t", "]]", "[["]
garbage = st.one_of(
    st.lists(st.sampled_from(TOKENS), max_size=60).map("".join),
    st.text(max_size=200),
    st.binary(max_size=200).map(lambda b: b.decode("utf-8", "replace")),
    st.binary(max_size=200).map(lambda b: b.decode("latin-1")),
)


@settings(max_examples=500, deadline=None)
@given(text=garbage)
def test_arbitrary_text_raises_only_gcodekit_errors(text):
    store = ParameterStore()
    store.set("a", 1.0)
    try:
        value = evaluate(text, store)
    except GcodeError as exc:
        assert 1 <= exc.diagnostic.column <= len(text) + 1
    else:
        assert math.isfinite(value)
