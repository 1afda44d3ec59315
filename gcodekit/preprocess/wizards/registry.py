"""Wizard functions by name: :class:`WizardRegistry` and the default registry's module-level functions."""

from __future__ import annotations

import re
import warnings
from typing import Callable

from ...errors import ConfigError, did_you_mean
from .builtins import BUILTINS
from .context import WizardFunction

# A wizard name: two ASCII letters, then letters, digits or '_' (GER: "wizard
# commands must start with two consecutive letters").
NAME = re.compile(r"[A-Za-z]{2}[A-Za-z0-9_]*")


class WizardWarning(UserWarning):
    """A wizard name is registered twice."""


class WizardRegistry:
    """Wizard functions keyed by name, matched case-insensitively.

    Parameters
    ----------
    builtins : bool, default: True
        Start with the built-in wizards (``Pocket``, ``CirclePocket``,
        ``DrillGrid``, ``BoltCircle``, ``Face``).

    Examples
    --------
    >>> reg = WizardRegistry(builtins=False)
    >>> _ = reg.register("Hello", lambda ctx, who: [f"(hello {who})"])
    >>> reg.get("HELLO") is reg.get("hello"), reg.names()
    (True, ['Hello'])
    """

    def __init__(self, *, builtins: bool = True):
        self._items: dict[str, tuple[str, WizardFunction]] = {}
        if builtins:
            for name, function in BUILTINS.items():
                self.register(name, function)

    def register(self, name: str, function: WizardFunction, *, replace: bool = False) -> WizardFunction:
        """Register ``function`` as wizard ``name``; returns ``function``.

        A name already taken (in any case) by another function warns
        (:class:`WizardWarning`) and keeps the old one, unless ``replace``.

        Raises
        ------
        ConfigError
            ``name`` does not start with two letters.
        TypeError
            ``function`` is not callable.
        """
        if not isinstance(name, str) or not NAME.fullmatch(name):
            raise ConfigError(f"wizard name {name!r} must be two letters then letters, digits or '_'")
        if not callable(function):
            raise TypeError(f"wizard {name!r}: {function!r} is not callable")
        key = name.lower()
        old = self._items.get(key)
        if old is not None and old[1] is not function and not replace:
            warnings.warn(f"wizard {name!r} is already registered as {old[0]!r} ({_describe(old[1])}); "
                          "keeping it (pass replace=True to replace it)", WizardWarning, stacklevel=3)
            return function
        self._items[key] = (name, function)
        return function

    def unregister(self, name: str) -> WizardFunction:
        """Remove wizard ``name`` and return its function; KeyError if absent."""
        try:
            return self._items.pop(str(name).lower())[1]
        except KeyError:
            raise KeyError(f"no wizard {name!r}{did_you_mean(str(name), self.names())}") from None

    def get(self, name: str) -> WizardFunction | None:
        """The function of wizard ``name`` (any case), or None."""
        item = self._items.get(name.lower())
        return None if item is None else item[1]

    def name_of(self, name: str) -> str | None:
        """The name as registered."""
        item = self._items.get(name.lower())
        return None if item is None else item[0]

    def names(self) -> list[str]:
        """Registered names, as written, sorted case-insensitively."""
        return sorted((n for n, _ in self._items.values()), key=str.lower)

    def as_dict(self) -> dict[str, WizardFunction]:
        return {n: self._items[n.lower()][1] for n in self.names()}

    def copy(self) -> WizardRegistry:
        new = WizardRegistry(builtins=False)
        new._items = dict(self._items)
        return new

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name.lower() in self._items

    def __len__(self) -> int:
        return len(self._items)


def _describe(function: Callable) -> str:
    return getattr(function, "__qualname__", None) or repr(function)


def register_wizard(name: str, function: WizardFunction, *, replace: bool = False) -> WizardFunction:
    """Register a wizard in the default registry (see :meth:`WizardRegistry.register`).

    Examples
    --------
    >>> _ = register_wizard("Greet", lambda ctx, who: [f"(hello {who})"])
    >>> "Greet" in wizards()
    True
    >>> _ = unregister_wizard("Greet")
    """
    return DEFAULT_REGISTRY.register(name, function, replace=replace)


def unregister_wizard(name: str) -> WizardFunction:
    """Remove a wizard from the default registry; returns its function."""
    return DEFAULT_REGISTRY.unregister(name)


def wizards() -> dict[str, WizardFunction]:
    """The default registry's wizards, name to function, sorted by name."""
    return DEFAULT_REGISTRY.as_dict()


def wizard(name: str | None = None, *, replace: bool = False,
           registry: WizardRegistry | None = None) -> Callable[[WizardFunction], WizardFunction]:
    """Decorator form of :func:`register_wizard`; the name defaults to the function's.

    Examples
    --------
    >>> @wizard("Spot", registry=WizardRegistry(builtins=False))
    ... def spot(ctx, x: float, y: float):
    ...     return [f"G0 X{x} Y{y}", "G1 Z-0.1 F10", "G0 Z0.1"]
    """

    def decorate(function: WizardFunction) -> WizardFunction:
        reg = DEFAULT_REGISTRY if registry is None else registry
        reg.register(name or function.__name__, function, replace=replace)
        return function

    return decorate


#: The registry :class:`WizardStage` uses by default, with the built-ins.
DEFAULT_REGISTRY = WizardRegistry()
