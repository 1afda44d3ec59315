"""O-words of one file matched with each other, and its subroutines and programs registered.

Matching links ``if`` to ``elseif``/``else``/``endif``, ``while`` to
``endwhile``, ``do`` to its closing ``while``, ``repeat`` to ``endrepeat``
and ``sub`` to ``endsub`` (the ``start``, ``end`` and ``next`` indices of
:class:`~.statements.OWord`), once, before anything runs.  A mistake in the
structure is reported at the O-word's file, line and column and leaves that
O-word (and what it opened) out of the run.
"""

from __future__ import annotations

from typing import Callable

from .statements import Code, OWord, Report

#: What closes each opening O-word, and what each closing one closes
_CLOSER = {"sub": "endsub", "if": "endif", "while": "endwhile", "do": "while", "repeat": "endrepeat"}
_CLOSES = {"endsub": "sub", "endif": "if", "endwhile": "while", "endrepeat": "repeat"}

#: Subroutines (``o<name> sub``) or Fanuc programs (``O1000``): label to (file, index)
Table = dict[str, tuple[Code, int]]


def link(code: Code, subs: Table, programs: Table, report: Report, ends_program: Callable[[str], bool], *,
         main: bool = False) -> Code:
    """Match the O-words of ``code`` and register its subs and programs; returns ``code``.

    A main program titled with a program number (``O1`` first) must end
    (``ends_program``: M2/M30) before its first ``o- sub``, as rs274 requires.
    """
    _Linker(code.items, report).run(code, subs, programs, ends_program, main)
    return code


class _Linker:
    """The open O-words while one file is matched."""

    def __init__(self, items: list, report: Report):
        self.items = items
        self.report = report
        self.stack: list[int] = []  # indices of the O-words still open
        self.branches: dict[int, list[int]] = {}  # an open if's branches so far

    def run(self, code: Code, subs: Table, programs: Table, ends_program: Callable[[str], bool], main: bool) -> None:
        items, stack, branches = self.items, self.stack, self.branches
        title = _program_title(items) if main else None
        for i, st in enumerate(items):
            if title is not None and not isinstance(st, OWord) and ends_program(st.text):
                title = None  # the titled main program has ended
            if not isinstance(st, OWord) or not st.valid:
                continue
            k = st.keyword
            if k == "sub" and title is not None and i > title:
                self.report(st.line, st.column, f"{st.name} found in an illegal location: the main program "
                            f"{items[title].name} must end with M2 or M30 before its subroutines")
                title = None
            if k == "sub":
                if stack:
                    self.report(st.line, st.column, f"{st.name} inside {items[stack[-1]].name}: "
                                "subroutines cannot be nested")
                    st.valid = False
                    continue
                if st.label in subs:
                    where = subs[st.label]
                    self.report(st.line, st.column, f"{st.name} is already defined at "
                                f"{where[0].file}:{where[0].items[where[1]].line.line}")
                else:
                    subs[st.label] = (code, i)
                stack.append(i)
            elif k == "":
                programs.setdefault(st.label, (code, i))
            elif k == "while" and (j := self._open(st, ("do",), quiet=True)) is not None:
                self._unwind(j, st)
                stack.pop()
                st.start, items[j].end = j, i
            elif k in ("if", "while", "do", "repeat"):
                if k == "if":
                    branches[i] = [i]
                stack.append(i)
            elif k in _CLOSES:
                self._close(i, st)
            elif k in ("elseif", "else"):
                self._branch(i, st)
            elif k in ("break", "continue"):  # rs274 2.9 refuses them in a repeat loop, run or not
                j = self._open(st, ("while", "do"))
                if j is not None:
                    st.start = j
            elif k == "return":
                # rs274 returns from the enclosing sub whatever the return's own label
                # (LinuxCNC's retval.ngc writes "o1010 return" inside "o1000 sub")
                if not stack or items[stack[0]].keyword != "sub":
                    self.report(st.line, st.column, f"{st.name} is not inside a subroutine")
                    st.valid = False
        for j in reversed(stack):
            self._unclosed(j, None)

    def _close(self, i: int, st: OWord) -> None:
        """``endsub``, ``endif``, ``endwhile`` or ``endrepeat`` at index ``i``."""
        items = self.items
        j = self._open(st, (_CLOSES[st.keyword],))
        if j is None:
            return
        self._unwind(j, st)
        self.stack.pop()
        st.start, items[j].end = j, i
        if st.keyword == "endif":
            chain = self.branches.pop(j) + [i]
            for a, b in zip(chain, chain[1:]):
                items[a].next = b
                items[b].start, items[b].end = j, i

    def _branch(self, i: int, st: OWord) -> None:
        """``elseif`` or ``else`` at index ``i``: the next branch of the open ``if``."""
        j = self._open(st, ("if",))
        if j is None:
            return
        self._unwind(j, st)
        chain = self.branches[j]
        last = self.items[chain[-1]]
        if last.keyword == "else":
            self.report(st.line, st.column, f"{st.name} after {last.name}")
            st.valid = False
        else:
            chain.append(i)

    def _open(self, st: OWord, kinds: tuple[str, ...], *, quiet: bool = False) -> int | None:
        """Index of the innermost open O-word of ``kinds`` with ``st``'s label."""
        items, stack = self.items, self.stack
        for j in reversed(stack):
            opener = items[j]
            if opener.keyword == "sub":
                break
            if opener.keyword in kinds and opener.label == st.label:
                return j
        if not quiet and "sub" in kinds and stack and items[stack[0]].label == st.label:
            return stack[0]
        if not quiet:
            what = " or ".join(kinds)
            self.report(st.line, st.column, f"{st.name} without a matching o{st.label} {what}")
            st.valid = False
        return None

    def _unwind(self, j: int, st: OWord) -> None:
        """Close, as errors, what is still open above index ``j`` of the stack."""
        while self.stack[-1] != j:
            self._unclosed(self.stack.pop(), st)

    def _unclosed(self, j: int, at: OWord | None) -> None:
        opener = self.items[j]
        closer = _CLOSER[opener.keyword]
        where = f"before {at.name} on line {at.line.line}" if at else "at the end of the file"
        self.report(opener.line, opener.column, f"{opener.name} is not closed by o{opener.label} {closer} {where}")
        if opener.keyword != "sub":  # an open sub still runs to the end of its file
            opener.valid = False
            for b in self.branches.pop(j, []):
                self.items[b].valid = False


def _program_title(items: list) -> int | None:
    """Index of a program-number O-word (``O1``) that opens the file before any code, else None."""
    for i, st in enumerate(items):
        if isinstance(st, OWord):
            return i if st.keyword == "" and st.valid else None
        if st.text.strip() and not st.text.strip().startswith(("(", ";", "%")):
            return None
    return None
