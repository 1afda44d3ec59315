"""Syntax stage: load and validate flavor files (``flavors/<name>.toml``).

Validation is strict, like Klipper's config: an unknown key, a wrong type or
a value outside the vocabulary raises :class:`~gcodekit.errors.ConfigError`
naming the file, the table and the key, with a did-you-mean when a close
spelling exists.  A file may start from another with ``inherit = "name"``:
scalars and lists replace the parent's, the ``[words]``, ``[codes]``,
``[firmware_codes]`` and ``[detect]`` tables merge key by key, and a word or
code mapped to ``""`` is removed; the chain of parents is kept as the
flavor's ``lineage``.
"""

from __future__ import annotations

import functools
import os
import re
import tomllib
from dataclasses import MISSING, fields
from pathlib import Path
from types import MappingProxyType
from typing import Any

from ..errors import ConfigError, did_you_mean
from .flavor import BLOCK_SPLITS, COMMANDS, PARAMETERS, ZERO_FEEDS, DetectRules, Flavor

FLAVOR_DIR = Path(__file__).with_name("flavors")

#: Tables of a flavor file; every other key is a top-level value.
_TABLES = ("words", "codes", "firmware_codes", "detect")
#: Keys that are not Flavor fields.
_EXTRA_KEYS = ("inherit",)
#: Flavor fields the loader sets, not the file.
_LOADER_FIELDS = ("lineage",)
#: Codes are written as in the program but normalized: upper case, no
#: leading zeros (``G1``, ``G38.2``, ``M104``); extended commands are names.
_GM_CODE = re.compile(r"[GM](?:0|[1-9]\d*)(?:\.\d+)?")
_GM_PADDED = re.compile(r"([GM])0+(\d.*)")
_NAME_CODE = re.compile(r"[A-Z][A-Z0-9_]*[A-Z0-9]")
_CHOICES = {
    "block_split": BLOCK_SPLITS,
    "units": ("mm", "inch"),
    "extrusion": ("absolute", "relative", ""),
    "comment": (";", "(", ""),
    "initial_motion": ("", "rapid", "linear"),
    "zero_feed": ZERO_FEEDS,
}


def _kind(default: Any) -> str:
    """Name the TOML type a field takes, from its dataclass default."""
    for kind, types in (("bool", bool), ("int", int), ("str", str), ("list", (tuple, frozenset))):
        if isinstance(default, types):
            return kind
    return "table"


def _schema(cls: type) -> dict[str, str]:
    """Key -> kind for a dataclass: ``bool``, ``int``, ``str``, ``list``, ``table``."""
    out = {}
    for f in fields(cls):
        if f.default is not MISSING:
            out[f.name] = _kind(f.default)
        else:  # required (name) or a default_factory mapping
            out[f.name] = "str" if f.default_factory is MISSING else "table"
    return out


_FLAVOR_KEYS = ({k: v for k, v in _schema(Flavor).items() if k not in _LOADER_FIELDS}
                | dict.fromkeys(_EXTRA_KEYS, "str"))
_DEFAULTS = {f.name: f.default for f in fields(Flavor)}
_DETECT_KEYS = _schema(DetectRules)


def list_flavors() -> list[str]:
    """Names of the flavors bundled with gcodekit.

    Examples
    --------
    >>> "marlin" in list_flavors()
    True
    """
    return sorted(p.stem for p in FLAVOR_DIR.glob("*.toml"))


def load_flavor(name_or_path: str | os.PathLike[str]) -> Flavor:
    """Load a flavor by bundled name or from a ``.toml`` file.

    Parameters
    ----------
    name_or_path : str or path-like
        A name from :func:`list_flavors` (``"marlin"``) or the path of a
        flavor file.

    Returns
    -------
    Flavor
        Cached: loading the same file twice returns the same object.

    Raises
    ------
    ConfigError
        Unknown name, unreadable file, bad TOML, unknown key, wrong type or
        value; the message names the file, the table and the key.

    See Also
    --------
    list_flavors, gcodekit.syntax.detect_flavor

    Examples
    --------
    Codes map to gcodekit's normalized command names.

    >>> flavor = load_flavor("marlin")
    >>> flavor.command("G1"), flavor.words["E"]
    ('linear', 'e')
    """
    text = os.fspath(name_or_path)
    if text.endswith(".toml") or os.sep in text or "/" in text:
        path = Path(text)
    else:
        names = list_flavors()
        if text not in names:
            raise ConfigError(
                f"unknown flavor {text!r}{did_you_mean(text, names)}; "
                f"bundled flavors: {', '.join(names)}"
            )
        path = FLAVOR_DIR / f"{text}.toml"
    return _load_path(path.resolve())


@functools.lru_cache(maxsize=None)
def _load_path(path: Path) -> Flavor:
    return _build(_resolve(path, ()), path)


def _read(path: Path) -> dict[str, Any]:
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read flavor file: {exc.strerror}") from exc
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: invalid TOML: {exc}") from exc


def _resolve(path: Path, seen: tuple[Path, ...]) -> dict[str, Any]:
    """Read, check and merge one file onto the file it inherits from."""
    if path in seen:
        chain = " -> ".join(p.name for p in (*seen, path))
        raise ConfigError(f"{path}: inherit: circular inheritance {chain}")
    raw = _read(path)
    _check(raw, path)
    parent_name = raw.pop("inherit", None)
    if parent_name is None:
        return raw
    sibling = path.with_name(f"{parent_name}.toml")
    parent_path = sibling if sibling.exists() else FLAVOR_DIR / f"{parent_name}.toml"
    if not parent_path.exists():
        names = list_flavors()
        raise ConfigError(
            f"{path}: inherit: unknown flavor {parent_name!r}{did_you_mean(parent_name, names)}"
        )
    merged = _resolve(parent_path.resolve(), (*seen, path))
    lineage = (parent_name, *merged.get("lineage", ()))
    for key, value in raw.items():
        if key in _TABLES:
            merged[key] = {**merged.get(key, {}), **value}
        else:
            merged[key] = value
    merged["lineage"] = lineage
    return merged


def _where(path: Path, table: str | None, key: str) -> str:
    return f"{path}: [{table}] {key}" if table else f"{path}: {key}"


def _check(raw: dict[str, Any], path: Path) -> None:
    """Check one file's keys and value types before merging."""
    _check_table(raw, _FLAVOR_KEYS, path, None)
    if "detect" in raw:
        _check_table(raw["detect"], _DETECT_KEYS, path, "detect")
    for letter, param in raw.get("words", {}).items():
        where = _where(path, "words", letter)
        if not re.fullmatch(r"[A-Z]", letter) or letter in "GM":
            raise ConfigError(f"{where}: a word is one upper-case letter other than G and M")
        if param != "" and param not in PARAMETERS:
            raise ConfigError(
                f"{where}: {param!r} is not a parameter name{did_you_mean(str(param), PARAMETERS)}"
            )
    for code, what in raw.get("firmware_codes", {}).items():
        _check_code(code, _where(path, "firmware_codes", code))
        if not isinstance(what, str):
            raise ConfigError(f"{_where(path, 'firmware_codes', code)}: expected a string saying what the code does")
    for code, command in raw.get("codes", {}).items():
        _check_code(code, _where(path, "codes", code))
        if command != "" and command not in COMMANDS:
            raise ConfigError(
                f"{_where(path, 'codes', code)}: {command!r} is not a command name"
                f"{did_you_mean(str(command), COMMANDS)}"
            )


def _check_table(table: dict[str, Any], schema: dict[str, str], path: Path, name: str | None) -> None:
    for key, value in table.items():
        where = _where(path, name, key)
        kind = schema.get(key)
        if kind is None:
            raise ConfigError(f"{where}: unknown key{did_you_mean(key, schema)}")
        ok = {
            "bool": isinstance(value, bool),
            "int": isinstance(value, int) and not isinstance(value, bool),
            "str": isinstance(value, str),
            "list": isinstance(value, list) and all(isinstance(v, str) for v in value),
            "table": isinstance(value, dict),
        }[kind]
        if not ok:
            expected = {
                "bool": "true or false",
                "int": "an integer",
                "str": "a string",
                "list": "a list of strings",
                "table": "a table",
            }[kind]
            raise ConfigError(f"{where}: expected {expected}, got {value!r}")
        if key in _CHOICES and value not in _CHOICES[key]:
            raise ConfigError(
                f"{where}: {value!r} is not one of {', '.join(map(repr, _CHOICES[key]))}"
                + did_you_mean(value, _CHOICES[key])
            )


def _check_code(code: str, where: str) -> None:
    padded = _GM_PADDED.fullmatch(code)
    if padded:
        raise ConfigError(f"{where}: write codes without leading zeros: {''.join(padded.groups())!r}")
    if not (_GM_CODE.fullmatch(code) or _NAME_CODE.fullmatch(code)):
        raise ConfigError(f"{where}: not a code such as 'G1', 'M104' or 'SET_VELOCITY_LIMIT'")


def _check_regex(pattern: str, where: str, *, group: bool = False) -> None:
    try:
        compiled = re.compile(pattern)
    except re.error as exc:
        raise ConfigError(f"{where}: invalid regular expression {pattern!r}: {exc}") from exc
    if group and compiled.groups < 1:
        raise ConfigError(f"{where}: regular expression {pattern!r} needs a (group)")


def _build(data: dict[str, Any], path: Path) -> Flavor:
    """Check the merged values against each other and build the Flavor."""
    if "name" not in data:
        raise ConfigError(f"{path}: name: missing required key")
    words = {k: v for k, v in data.get("words", {}).items() if v}
    codes = {k: v for k, v in data.get("codes", {}).items() if v}
    firmware_codes = {k: v for k, v in data.get("firmware_codes", {}).items() if v and k not in codes}
    detect = dict(data.get("detect", {}))

    def get(key: str) -> Any:
        return data.get(key, _DEFAULTS[key])

    for sep in get("statement_separators"):
        if sep in get("line_comments"):
            raise ConfigError(
                f"{path}: statement_separators: {sep!r} is also in line_comments; "
                "a character is either a separator or a comment"
            )
    if get("multiline_comments") and not get("paren_comments"):
        raise ConfigError(f"{path}: multiline_comments: needs paren_comments = true")
    letter = get("line_number_letter")
    if letter and not re.fullmatch(r"[A-Z]", letter):
        raise ConfigError(f"{path}: line_number_letter: {letter!r} is not '' or one upper-case letter")
    for word, param in words.items():
        if param == "line_number" and word != letter:
            raise ConfigError(
                f"{path}: [words] {word}: maps to 'line_number' but line_number_letter is {letter!r}"
            )
    if not (get("extended_commands") or get("assignments")):
        for code in codes:
            if not _GM_CODE.fullmatch(code):
                raise ConfigError(
                    f"{path}: [codes] {code}: named commands need extended_commands = true "
                    "(or assignments = true for Sinumerik names)"
                )
    for key in ("string_codes", "other_codes"):
        for code in get(key):
            _check_code(code, f"{path}: {key}: {code}")
    for code in detect.get("codes", ()):
        _check_code(code, f"{path}: [detect] codes: {code}")
    for pattern in get("layer_comments"):
        _check_regex(pattern, f"{path}: layer_comments")
    if get("feature_comment"):
        _check_regex(get("feature_comment"), f"{path}: feature_comment", group=True)
    for key in ("header", "hints", "against"):
        for pattern in detect.get(key, ()):
            _check_regex(pattern, f"{path}: [detect] {key}")
    for key in ("extensions", "shared_extensions"):
        for ext in detect.get(key, ()):
            if not re.fullmatch(r"\.[A-Za-z0-9_.]+", ext):
                raise ConfigError(f"{path}: [detect] {key}: {ext!r} is not a suffix such as '.ngc'")

    values: dict[str, Any] = {}
    for key, kind in _FLAVOR_KEYS.items():
        if key in data and kind == "list":
            values[key] = frozenset(data[key]) if key in ("string_codes", "other_codes") else tuple(data[key])
        elif key in data and kind != "table" and key not in _EXTRA_KEYS:
            values[key] = data[key]
    rules = {k: tuple(v) if isinstance(v, list) else v for k, v in detect.items()}
    for key in ("extensions", "shared_extensions"):
        rules[key] = tuple(e.lower() for e in rules.get(key, ()))
    return Flavor(
        **values,
        words=MappingProxyType(words),
        codes=MappingProxyType(codes),
        firmware_codes=MappingProxyType(firmware_codes),
        detect=DetectRules(**rules),
        lineage=data.get("lineage", ()),
    )
