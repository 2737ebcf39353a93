"""Located YAML/JSON documents: bounded reading, safe parsing, duplicate keys refused, field locations mapped to
lines, and a field reader whose errors are one line naming the file, line and field (robot descriptions, parking
problems, camera and points files, slip weights).

YAML goes through ``yaml.SafeLoader`` only; user text is never evaluated.
"""

from __future__ import annotations

import difflib
import json
import os
import reprlib
import sys
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import yaml

from ._atomic import atomic_path
from .errors import DescriptionError
from .limits import _check_size, regular_file_problem
from .units import UnitError, parse_quantity

__all__ = ["FieldReader", "LineOf", "Loc", "compose", "hint", "line_finder", "parse_document", "read_document",
           "read_file", "short_repr"]

#: A field's location: keys and list indices from the document's root.
Loc = tuple[str | int, ...]
#: Maps a location to its 1-based line, or None.
LineOf = Callable[[Loc], int | None]

#: Bounded repr of a value quoted in an error: an aliased YAML "billion laughs" list (9 aliases, 9 deep) given as a
#: name was written out whole, 4e8 items, and the error never came.
_SHORT = reprlib.Repr()
_SHORT.maxstring = _SHORT.maxother = 80
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxdict = 2, 4, 4


def short_repr(value: Any) -> str:
    """`value`'s repr for an error message, bounded (:data:`_SHORT`) whatever its size or depth."""
    return _SHORT.repr(value)


def read_file(path: str | os.PathLike[str], what: str = "description") -> str:
    """The UTF-8 text of the document file `path` (a `what`), at most :data:`wmrkit.limits.MAX_FILE_SIZE` bytes,
    without the byte order mark Windows editors write (``json`` refused it); a :class:`DescriptionError` naming the
    file and the reason when it cannot be read."""
    path = Path(path)
    problem = regular_file_problem(path, what)
    if problem:
        raise DescriptionError(problem, source=str(path))
    try:
        _check_size(path.stat().st_size, "bytes", str(path), what)
        return path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as err:
        reason = getattr(err, "strerror", None) or err  # UnicodeDecodeError has no strerror
        raise DescriptionError(f"cannot read the file ({err.__class__.__name__}: {reason})",
                               source=str(path)) from None


def write_document(path: str | os.PathLike[str], data: Any) -> None:
    """Write `data` to `path` as JSON (a ``.json`` name) or YAML (any other), replacing the file in one step
    (:func:`wmrkit._atomic.atomic_path`: a failed write leaves the old file whole); what :func:`read_document`
    reads back."""
    text = (json.dumps(data, indent=2) + "\n" if Path(path).suffix.lower() == ".json"
            else yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
    with atomic_path(path) as scratch:
        scratch.write_text(text, encoding="utf-8")


def read_document(text: str, source: str, fmt: str = "yaml") -> tuple[Any, LineOf]:
    """``(data, line_of)`` of document `text` (``fmt`` "yaml" or "json"): parsed once, duplicate keys refused;
    the lines of a JSON document are found (by composing it as YAML) only when an error asks, and only for texts
    up to 64 kB."""
    root, data = parse_document(text, source, fmt)
    if fmt != "json":
        return data, line_finder(root)
    if len(text) > 1 << 16:
        return data, lambda loc: None
    return data, lambda loc: line_finder(compose(text))(loc)


class FieldReader:
    """Reads the fields of a located document and raises :class:`DescriptionError` at their location.

    ``wheels``: names of the wheels read so far (a robot description names the wheel of an error).
    """

    def __init__(self, source: str, line_of: LineOf) -> None:
        self.source, self.line_of = source, line_of
        self.wheels: list[str | None] = []  # None until the wheel's name is known

    def fail(self, message: str, loc: Loc) -> None:
        """Raise :class:`DescriptionError` `message` at `loc` (its line and wheel when known)."""
        wheel = None
        if len(loc) >= 2 and loc[0] == "wheels" and isinstance(loc[1], int) and loc[1] < len(self.wheels):
            wheel = self.wheels[loc[1]]
        raise DescriptionError(message, source=self.source, loc=loc, line=self.line_of(loc), wheel=wheel)

    def require(self, data: Mapping[str, Any], key: str, loc: Loc) -> Any:
        """``data[key]``; a missing field is an error."""
        if key not in data:
            self.fail(f"missing field '{key}'", (*loc, key) if not loc else loc)
        return data[key]

    def text(self, data: Mapping[str, Any], key: str, loc: Loc, *, required: bool = True) -> str:
        """A non-empty string field (an empty string when absent and not `required`)."""
        if key not in data and not required:
            return ""
        value = self.require(data, key, loc)
        if not isinstance(value, str) or (required and not value.strip()):
            self.fail(f"must be a non-empty string, got {short_repr(value)}", (*loc, key))
        return value

    def quantity(self, value: Any, kind: str, loc: Loc) -> float:
        """`value` in SI units (:func:`wmrkit.units.parse_quantity` of `kind`)."""
        try:
            return parse_quantity(value, kind)  # type: ignore[arg-type]
        except UnitError as err:
            self.fail(str(err), loc)
        raise AssertionError  # unreachable: fail raises

    def joints(self, item: Mapping[str, Any], key: str, allowed: tuple[str, ...], loc: Loc) -> tuple[str, ...]:
        """A list of distinct joint names among `allowed`, in `allowed` order."""
        value = item.get(key, [])
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, list) or not all(isinstance(j, str) for j in value):
            self.fail(f"must be a list of joint names (any of: {', '.join(allowed)})", (*loc, key))
        for j, joint in enumerate(value):
            if joint not in allowed:
                self.fail(f"no joint '{joint}' on a {item.get('type')} wheel{hint(joint, allowed)} "
                          f"(joints: {', '.join(allowed)})", (*loc, key, j))
            if joint in value[:j]:
                self.fail(f"joint '{joint}' listed twice", (*loc, key, j))
        return tuple(sorted(value, key=allowed.index))

    def reject_unknown(self, data: Mapping[str, Any], allowed: tuple[str, ...], loc: Loc) -> None:
        """Refuse any field of `data` not in `allowed`, with a did-you-mean."""
        for key in data:
            if not isinstance(key, str):
                self.fail(f"field names are strings, got {key!r}", loc)
            if key not in allowed:
                self.fail(f"unknown field '{key}'{hint(key, allowed)}", (*loc, key))


#: words users bring from other tools for a field spelled otherwise here (suggested when that field is allowed)
SYNONYMS = {"radius": "r", "wheel_radius": "r", "roller_radius": "r_r", "offset": "d", "castor_offset": "d",
            "angle": "heading", "steering": "heading", "steer": "heading", "yaw": "heading", "pos": "position",
            "xy": "position", "location": "position", "translation": "position"}


def hint(word: str, choices: Any) -> str:
    """`` (did you mean '...'?)`` for the closest of `choices` (or its synonym among them), or an empty string."""
    choices = list(choices)
    alias = SYNONYMS.get(str(word).lower())
    if alias in choices:
        return f" (did you mean '{alias}'?)"
    close = difflib.get_close_matches(str(word), choices, n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""


def parse_document(text: str, source: str, fmt: str) -> tuple[yaml.Node | None, Any]:
    """``(node tree or None, data)`` of `text`: JSON by ``json`` (no node tree), YAML composed once, checked for
    duplicate keys, then constructed from the nodes."""
    if fmt == "json":
        try:
            return None, json.loads(text, object_pairs_hook=_JsonPairs(text, source))
        except DescriptionError:
            raise
        except json.JSONDecodeError as err:
            raise DescriptionError(f"malformed JSON: {err.msg} (column {err.colno})", source=source,
                                   line=err.lineno) from None
        except RecursionError:
            raise DescriptionError("malformed JSON: nesting too deep", source=source) from None
        except ValueError as err:  # integers of > 4300 digits (Python's words: "use sys.set_int_max_str_digits()")
            what = (f"a number of more than {sys.get_int_max_str_digits()} digits" if "integer string" in str(err)
                    else str(err).splitlines()[0])
            raise DescriptionError(f"malformed JSON: {what}", source=source) from None
    root = None
    try:
        loader = _SafeLoader(text)  # the reader already rejects some characters
        try:
            root = loader.get_single_node()
            _reject_duplicate_keys(root, source)
            return root, None if root is None else loader.construct_document(root)
        finally:
            loader.dispose()
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        loc, wheel = _node_at(root, mark)  # a value the constructors refuse ('010'): its field and wheel
        raise DescriptionError(f"malformed YAML: {problem}", source=source, loc=loc, wheel=wheel,
                               line=None if mark is None else mark.line + 1) from None
    except RecursionError:
        raise DescriptionError("malformed YAML: nesting too deep", source=source) from None


class _JsonPairs:
    """``object_pairs_hook`` of ``json.loads`` refusing a key given twice (JSON parsers keep the last one)."""

    def __init__(self, text: str, source: str) -> None:
        self.text, self.source = text, source

    def __call__(self, pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        out = dict(pairs)
        if len(out) != len(pairs):
            seen: set[str] = set()
            key = next(k for k, _ in pairs if k in seen or seen.add(k))
            _reject_duplicate_keys(compose(self.text), self.source)  # locates it when the text composes as YAML
            raise DescriptionError(f"field '{key}' given twice", source=self.source)
        return out


class _SafeLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` whose constructors fail with a located YAML error, never a bare ValueError."""

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:
        try:
            return super().construct_object(node, deep=deep)
        except (ValueError, TypeError, KeyError, AttributeError, OverflowError) as err:  # e.g. "2020-13-45"
            what = repr(node.value[:40]) if isinstance(node.value, str) else "this node"
            raise yaml.constructor.ConstructorError(
                None, None, f"cannot read {what} as {node.tag.rsplit(':', 1)[-1]} ({err})", node.start_mark
            ) from None


def _plain_number(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> int | float:
    """A YAML int or float, refused (a located error) where YAML 1.1 reads it otherwise than it looks: ``010`` as
    the octal 8, ``1:30`` as the sexagesimal 90 (JSON refuses both, YAML 1.2 reads 010 as 10)."""
    number = (yaml.SafeLoader.construct_yaml_int if node.tag.endswith(":int") else
              yaml.SafeLoader.construct_yaml_float)(loader, node)
    digits = node.value.lstrip("+-").replace("_", "")
    if ":" in digits or (digits.isdigit() and int(digits) != abs(number)):
        raise ValueError(f"YAML 1.1 reads it as {number!r}, not as it looks: write {number!r} if you mean it")
    return number


_SafeLoader.add_constructor("tag:yaml.org,2002:int", _plain_number)
_SafeLoader.add_constructor("tag:yaml.org,2002:float", _plain_number)


def compose(text: str) -> yaml.Node | None:
    """The YAML node tree of `text` (JSON is YAML enough for this), or None."""
    try:
        return yaml.compose(text, Loader=yaml.SafeLoader)
    except (yaml.YAMLError, RecursionError):
        return None


def _nodes(root: yaml.Node | None) -> Iterator[tuple[yaml.Node, Loc, str | None]]:
    """Each node of the tree `root` once (an alias's target once), with its location and the name of the wheel
    (``wheels[i]``) it belongs to, if any; a mapping comes before its values."""
    seen: set[int] = set()
    stack: list[tuple[yaml.Node | None, Loc, str | None]] = [(root, (), None)]
    while stack:
        node, loc, wheel = stack.pop()
        if node is None or id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            wheel = _wheel_name(node, loc) or wheel
            stack.extend((v, (*loc, k.value) if isinstance(k, yaml.ScalarNode) else loc, wheel) for k, v in node.value)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((v, (*loc, i), wheel) for i, v in enumerate(node.value))
        yield node, loc, wheel


def _node_at(root: yaml.Node | None, mark: yaml.Mark | None) -> tuple[Loc, str | None]:
    """Location and wheel of the innermost node of `root` that starts at `mark`, or ``((), None)``."""
    if root is None or mark is None:
        return (), None
    found = [(loc, wheel) for node, loc, wheel in _nodes(root) if node.start_mark.index == mark.index]
    return max(found, key=lambda f: len(f[0]), default=((), None))


def _reject_duplicate_keys(root: yaml.Node | None, source: str) -> None:
    """YAML and JSON parsers keep the last of two equal keys; a description must not say a field twice."""
    for node, loc, wheel in _nodes(root):
        if isinstance(node, yaml.MappingNode):
            keys: set[str] = set()
            for k, _ in node.value:
                if isinstance(k, yaml.ScalarNode) and k.value != "<<":
                    if k.value in keys:
                        raise DescriptionError(f"field '{k.value}' given twice", source=source, loc=(*loc, k.value),
                                               line=k.start_mark.line + 1, wheel=wheel)
                    keys.add(k.value)


def _wheel_name(node: yaml.MappingNode, loc: Loc) -> str | None:
    """The name of the wheel the mapping `node` at `loc` describes (``wheels[i]``), when it gives one."""
    if len(loc) != 2 or loc[0] != "wheels":
        return None
    return next((v.value for k, v in node.value if isinstance(k, yaml.ScalarNode) and k.value == "name"
                 and isinstance(v, yaml.ScalarNode)), None)


def line_finder(root: yaml.Node | None) -> LineOf:
    """Map a field location to its 1-based line in the node tree `root`."""

    def line_of(loc: Loc) -> int | None:
        node, line = root, None
        for part in loc:
            if isinstance(node, yaml.MappingNode):
                match = [(k, v) for k, v in node.value if k.value == part]
                if not match:
                    break
                line, node = match[0][0].start_mark.line + 1, match[0][1]
            elif isinstance(node, yaml.SequenceNode) and isinstance(part, int) and part < len(node.value):
                node = node.value[part]
                line = node.start_mark.line + 1
            else:
                break
        return line

    return line_of
