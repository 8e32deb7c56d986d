"""The key-line scanner and the error report of scene files: ``_key_lines`` maps every key path of valid TOML
text to the line it is written on (``tomllib`` reports no positions), and ``_Report`` collects every problem as
$file:line: key = value problem; what is valid$, raised together as one ``SceneFileError``."""

from __future__ import annotations

import re
import tomllib
from collections.abc import Mapping, Sequence
from typing import Any

from frustum._arrays import describe, escape_control
from frustum.errors import SceneFileError

_SPACES = re.compile(r"[ \t\r]*")


_BARE_KEY = re.compile(r"[\w-]*")  # letters, digits, "_" and "-"


_BARE_VALUE = re.compile(r"[^,\]}\n#]*")


_BASIC_STRING = re.compile(r'"((?:[^"\\\n]|\\.)*)"')


_LITERAL_STRING = re.compile(r"'([^'\n]*)'")


class _Scanner:
    """Map every key path (and array element) of valid TOML text to its 1-based line number."""

    def __init__(self, text: str) -> None:
        self.text, self.pos, self.line = text, 0, 1
        self.lines: dict[tuple, int] = {}
        self.array_tables: dict[tuple, int] = {}

    def _char(self) -> str:
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def _advance(self, count: int = 1) -> None:
        self.line += self.text.count("\n", self.pos, self.pos + count)
        self.pos += count

    def _skip_spaces(self) -> None:
        self.pos = _SPACES.match(self.text, self.pos).end()  # type: ignore[union-attr]

    def _skip_blank(self) -> None:
        """Spaces, newlines and comments (inside arrays)."""
        while self._char():
            char = self._char()
            if char in " \t\r\n":
                self._advance()
            elif char == "#":
                end = self.text.find("\n", self.pos)
                self.pos = len(self.text) if end < 0 else end
            else:
                return

    def _record(self, path: tuple) -> None:
        self.lines.setdefault(path, self.line)

    def _string(self) -> str:
        quote = self._char()
        triple = self.text.startswith(quote * 3, self.pos)
        if not triple:  # one-line strings (nearly all of them) in one regular-expression step
            found = (_BASIC_STRING if quote == '"' else _LITERAL_STRING).match(self.text, self.pos)
            if found:
                self.pos = found.end()
                body = found.group(1)
                return _unescape(body) if quote == '"' and "\\" in body else body
        start = self.pos + (3 if triple else 1)
        self._advance(start - self.pos)
        chars = []
        while self._char():
            if quote == '"' and self._char() == "\\":
                chars.append(self.text[self.pos : self.pos + 2])
                self._advance(2)
                continue
            if triple and self.text.startswith(quote * 3, self.pos):
                while self.text.startswith(quote * 4, self.pos):  # up to two quotes may end the content
                    chars.append(quote)
                    self._advance()
                self._advance(3)
                return "".join(chars)
            if not triple and self._char() == quote:
                self._advance()
                return _unescape("".join(chars)) if quote == '"' else "".join(chars)
            chars.append(self._char())
            self._advance()
        return "".join(chars)

    def _key(self) -> list[str]:
        parts = []
        while True:
            self._skip_spaces()
            if self._char() in ('"', "'"):
                parts.append(self._string())
            else:
                start = self.pos
                self.pos = _BARE_KEY.match(self.text, self.pos).end()  # type: ignore[union-attr]
                parts.append(self.text[start : self.pos])
            self._skip_spaces()
            if self._char() != ".":
                return parts
            self.pos += 1

    def _value(self, path: tuple) -> None:
        char = self._char()
        if char == "[":
            self._advance()
            index = 0
            while self._char():
                self._skip_blank()
                if self._char() == "]":
                    self._advance()
                    return
                self._record((*path, index))
                self._value((*path, index))
                index += 1
                self._skip_blank()
                if self._char() == ",":
                    self._advance()
            return
        if char == "{":
            self._advance()
            while self._char():
                self._skip_blank()
                if self._char() == "}":
                    self._advance()
                    return
                if self._char() == ",":
                    self._advance()
                    continue
                self._pair(path)
            return
        if char in ('"', "'"):
            self._string()
            return
        self.pos = _BARE_VALUE.match(self.text, self.pos).end()  # type: ignore[union-attr]

    def _pair(self, table: tuple) -> None:
        keys = self._key()
        for depth in range(1, len(keys) + 1):
            self._record((*table, *keys[:depth]))
        self._skip_spaces()
        if self._char() == "=":
            self.pos += 1
        self._skip_spaces()
        self._value((*table, *keys))

    def _resolve(self, parts: list[str], array: bool) -> tuple:
        path: tuple = ()
        for k, part in enumerate(parts):
            path = (*path, part)
            if array and k == len(parts) - 1:
                index = self.array_tables.get(path, 0)
                self.array_tables[path] = index + 1
                self._record(path)
                path = (*path, index)
            elif path in self.array_tables:
                path = (*path, self.array_tables[path] - 1)
        return path

    def scan(self) -> dict[tuple, int]:
        table: tuple = ()
        while self._char():
            self._skip_spaces()
            char = self._char()
            if char == "\n":
                self._advance()
            elif char == "#":
                end = self.text.find("\n", self.pos)
                self.pos = len(self.text) if end < 0 else end
            elif char == "[":
                array = self.text.startswith("[[", self.pos)
                self.pos += 2 if array else 1
                table = self._resolve(self._key(), array)
                self._record(table)
                end = self.text.find("\n", self.pos)
                self.pos = len(self.text) if end < 0 else end
            elif char:
                self._pair(table)
        return self.lines


def _unescape(raw: str) -> str:
    """The value of a TOML basic string's body (escapes such as \\u00e9 decoded), or `raw` if it is not one."""
    try:
        return tomllib.loads(f'v = "{raw}"')["v"]
    except tomllib.TOMLDecodeError:
        return raw


def _key_lines(text: str) -> dict[tuple, int]:
    """{key path: line} for valid TOML `text`; a path holds table keys and array indices, e.g. ("nodes", 0, "name")."""
    scanner = _Scanner(text)
    try:
        return scanner.scan()
    except (IndexError, ValueError):  # defensive: a scanner gap costs line numbers, never the validation
        return scanner.lines


def _path_text(path: Sequence) -> str:
    text = ""
    for part in path:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            bare = part.replace("_", "").replace("-", "").isalnum()
            shown = part if bare else f'"{escape_control(part)}"'
            text += ("." if text else "") + shown
    return text or "(file)"


def _problem_text(error: Exception) -> str:
    return escape_control(str(error).splitlines()[0]) if str(error) else type(error).__name__


def _toml_text(value: Any) -> str:
    """``describe(value)`` with booleans spelled as the scene file wrote them: ``[2.2, 1.6, false]``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list) and any(isinstance(v, bool) for v in value) and len(value) <= 16:
        return "[" + ", ".join(_toml_text(v) for v in value) + "]"
    return describe(value)


class _Report:
    """Collects every problem as $file:line: key = value problem; what is valid$."""

    def __init__(self, source: str, lines: dict[tuple, int] | str | None) -> None:
        self.source = source
        self._lines = lines  # TOML text: scanned for key lines only when a problem needs one
        self.problems: list[str] = []
        self.built: dict[tuple, Any] = {}  # (builder, arguments) -> result, for deterministic builders
        self.base: Any = "."  # the scene file's folder: relative image paths resolve against it

    @property
    def lines(self) -> dict[tuple, int] | None:
        if isinstance(self._lines, str):
            self._lines = _key_lines(self._lines)
        return self._lines

    def line(self, path: Sequence) -> int | None:
        if self.lines is None:
            return None
        path = tuple(path)
        while path:
            if path in self.lines:
                return self.lines[path]
            path = path[:-1]
        return 1

    def _where(self, path: Sequence) -> str:
        line = self.line(path)
        source = escape_control(self.source)
        return f"{source}:{line}" if line is not None else source

    def add(self, path: Sequence, value: Any, problem: str, valid: str) -> None:
        """$key = value problem; valid$."""
        self.problems.append(f"{self._where(path)}: {_path_text(path)} = {_toml_text(value)} {problem}; {valid}")

    def missing(self, path: Sequence, valid: str) -> None:
        self.problems.append(f"{self._where(path)}: {_path_text(path)} is missing; {valid}")

    def refused(self, path: Sequence, value: Any, error: Exception) -> None:
        """A value the building function refused: its own message says what is valid.

        When the message names one of the table's keys ($where: name = ...$), the problem points at that key.
        """
        message = _problem_text(error)
        named = re.match(r"[^:]*: (\w+)", message)
        if named and isinstance(value, Mapping):
            for key in (named.group(1), named.group(1) + "_deg"):
                if key in value:
                    path, value = (*path, key), value[key]
                    break
        self.problems.append(
            f"{self._where(path)}: {_path_text(path)} = {_toml_text(value)} is not accepted: {message}"
        )

    def raise_if_any(self) -> None:
        if self.problems:
            self.problems.sort(key=_line_of)
            count = len(self.problems)
            error = SceneFileError("\n".join(self.problems) + (f"\n({count} errors)" if count > 1 else ""))
            error.problems = list(self.problems)  # type: ignore[attr-defined]
            raise error


def _line_of(problem: str) -> int:
    """The line number a problem starts with (0 when it has none), for sorting the report."""
    found = re.match(r".*?:(\d+): ", problem)
    return int(found.group(1)) if found else 0


_BAD = object()
"""Marks a value that failed validation (its problem is already in the report)."""


def _bad(*values: Any) -> bool:
    """True if any value is ``_BAD`` (by identity: values may be numpy arrays)."""
    return any(value is _BAD for value in values)
