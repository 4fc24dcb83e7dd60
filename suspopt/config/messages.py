"""pydantic's validation errors in the user's terms: one module says every one of them.

:func:`plain_errors` turns the errors of one ``model_validate`` (``exc.errors()``) into
``(key path, message)`` pairs: the path is the YAML key's, without pydantic's union tags
and member labels (``road.bump_step.height`` is ``road.height``; a road's unknown ``kind``
is reported at ``road.kind``); the message is a plain sentence: what the key takes and what
it got, in YAML's spelling (``true``, ``.inf``, ``'text'``), with the field's unit and, for
a number out of its range that looks like a unit slip, the hint of
:mod:`suspopt.config.plausible`. pydantic's own wording ("Input should be", "Field
required", "type=...") is never passed on: an error type this module does not know is
said as "is not a valid value" with what was got.

The errors of the members of a union (``output.signals``: a list or ``'all'``) are said as
one: what each member takes, or the errors inside the member the value evidently meant (a
mapping given to ``over_scenarios`` is the ``{quantile: q}`` member's).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Sequence
from dataclasses import dataclass
from types import NoneType, UnionType
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import BaseModel

from ..errors import suggest
from .plausible import number, slip_hint

__all__ = ["plain_errors", "shown", "number", "suggest_words"]


# --- values as the user wrote them ---------------------------------------------------------


def shown(value: Any) -> str:
    """``value`` in YAML's terms, short: ``true``, ``.inf``, ``'text'``, ``a list``."""
    if value is None:
        return "an empty value"
    if isinstance(value, (bool, int, float)):
        return number(value)
    if isinstance(value, str):
        text = repr(value)
        return text if len(text) <= 40 else text[:36] + "...'"
    if isinstance(value, (list, tuple)):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    return "a value of another kind"


def _got(err: dict) -> str:
    """`` (got ...)`` for an error's input, or nothing when it has none."""
    return f" (got {shown(err['input'])})" if "input" in err else ""


def suggest_words(name: object, known: list[str]) -> list[str]:
    """The entries of ``known`` close to ``name`` (:func:`suspopt.errors.suggest`), or else
    those whose first words (``bump`` of ``bump_step``) are: ``bumpp`` is near ``bump``."""
    close = suggest(name, known)
    if close or not isinstance(name, str):
        return close
    words: dict[str, list[str]] = {}
    for option in known:
        parts = re.split(r"[_.]", str(option))
        for n in range(1, len(parts)):
            words.setdefault("_".join(parts[:n]), []).append(option)
    return list(dict.fromkeys(o for w in suggest(name, list(words)) for o in words[w]))[:3]


def _choices(text: str) -> list:
    """The options of pydantic's ``expected`` text (``'a', 'b' or 'c'``), as values."""
    body = re.sub(r" or (?=[^,]*$)", ", ", text)
    try:
        values = ast.literal_eval(f"[{body}]")
    except (ValueError, SyntaxError):
        return [text]
    return list(values)


def _unknown(
    what: str, value: Any, options: list, others: tuple = (), labels: list | None = None
) -> str:
    """``unknown road kind 'bumpp'; expected one of ... (did you mean 'bump_step'?)``:
    ``options`` the words allowed (shown as ``labels``), ``others`` what else is."""
    listed = ", ".join(str(o) for o in labels or options) + "".join(f", or {o}" for o in others)
    if not isinstance(value, str):
        return f"expected one of {listed} (got {shown(value)})"
    close = suggest_words(value, [str(o) for o in options])
    said = [repr(c) for c in close]
    said = [", ".join(said[:-1]), said[-1]] if len(said) > 2 else said
    mean = f" (did you mean {' or '.join(said)}?)" if close else ""
    return f"unknown {what} {shown(value)}; expected one of {listed}{mean}"


# --- the place of an error in the config's models ------------------------------------------


@dataclass
class _Place:
    """Where a pydantic location lies in the models: its key path (``loc``), the field at its
    end and the model holding that field (None when the path leaves the models), and where
    in the original location a union's member label stood (None if there is none); the
    ``annotation`` the path arrives at (None when it leaves the models)."""

    loc: tuple
    field: Any = None
    model: Any = None
    member_at: int | None = None
    annotation: Any = None


def _unwrap(annotation: Any) -> Any:
    """``annotation`` without ``Annotated`` and without ``None`` in a union of one type."""
    while get_origin(annotation) is Annotated:
        annotation = get_args(annotation)[0]
    if _is_union(annotation):
        members = [a for a in get_args(annotation) if a is not NoneType]
        if len(members) == 1:
            return _unwrap(members[0])
    return annotation


def _is_union(annotation: Any) -> bool:
    return get_origin(annotation) in (Union, UnionType)


def _is_model(annotation: Any) -> bool:
    return isinstance(annotation, type) and issubclass(annotation, BaseModel)


def _member(union: Any, part: Any) -> tuple[str, Any]:
    """What ``part`` is in a location at ``union``: ``("tag", member)`` for a discriminated
    union's tag (``bump_step``, ``semi_active``), ``("label", member)`` for pydantic's label
    of a member of a union told apart by trying each (a model's name, or ``list[str]``; the
    member None when only the label is known), ``("", None)`` for neither."""
    if not isinstance(part, str):
        return "", None
    for raw in get_args(union):
        tags = [m.tag for m in getattr(raw, "__metadata__", ()) if hasattr(m, "tag")]
        member = _unwrap(raw)
        if part in tags:
            return "tag", member
        if _is_model(member):
            kind = member.model_fields.get("kind")
            if kind and part in get_args(_unwrap(kind.annotation)):
                return "tag", member
            if part == member.__name__:
                return "label", member
        elif get_origin(member) is not None and part.startswith(
            getattr(get_origin(member), "__name__", "").lower()
        ):
            return "label", member
    if "[" in part or part in ("str", "int", "float", "bool", "none"):
        return "label", None
    return "", None


def _holding(union: Any, key: Any) -> Any:
    """The first model of ``union`` that has the field ``key`` (a key path without the
    union's tag: ``road.height``), else ``union``."""
    for raw in get_args(union):
        member = _unwrap(raw)
        if _is_model(member) and key in member.model_fields:
            return member
    return union


def _place(root: type, loc: tuple) -> _Place:
    """Walk the pydantic location ``loc`` through the models from ``root`` (the Config)."""
    place = _Place(())
    kept: list = []
    annotation: Any = root
    for i, part in enumerate(loc):
        if isinstance(part, str) and part.startswith("function-"):
            continue
        annotation = _unwrap(annotation)
        if _is_union(annotation):
            what, member = _member(annotation, part)
            if what:
                if what == "label" and place.member_at is None:
                    place.member_at = i
                annotation = member
                continue
            annotation = _holding(annotation, part)
        origin = get_origin(annotation)
        if _is_model(annotation):
            place.model, place.field = annotation, annotation.model_fields.get(part)
            annotation = place.field.annotation if place.field is not None else None
        elif origin in (list, tuple) and isinstance(part, int):
            annotation = get_args(annotation)[0] if get_args(annotation) else None
        elif origin is dict:
            annotation = get_args(annotation)[1] if get_args(annotation) else None
        else:
            place.model = place.field = annotation = None
        kept.append(part)
    place.loc, place.annotation = tuple(kept), annotation
    return place


def _unit(field: Any) -> str:
    """The unit a field's description gives (``[kg]``, ``[N s/m]``), or nothing."""
    for found in re.findall(r"\[([^\]]+)\]", getattr(field, "description", None) or ""):
        if re.fullmatch(r"[A-Za-z0-9/^ ()*.%-]{1,12}", found) and found not in ("-", "1"):
            return found
    return ""


def _tags(field: Any) -> list[str]:
    """The ``kind`` of each member of the discriminated union of ``field`` (a road's, a
    seat's), in their order."""
    union = _unwrap(getattr(field, "annotation", None))
    tags: list[str] = []
    for raw in get_args(union) if _is_union(union) else ():
        member = _unwrap(raw)
        kind = member.model_fields.get("kind") if _is_model(member) else None
        tags += (
            [t for t in get_args(_unwrap(kind.annotation)) if isinstance(t, str)] if kind else []
        )
    return tags


def _what(loc: tuple) -> str:
    """A key's name in a sentence: ``road kind`` for road.kind, else the key."""
    keys = [p for p in loc if isinstance(p, str)]
    if not keys:
        return "value"
    if keys[-1] == "kind" and len(keys) > 1:
        return f"{keys[-2]} kind"
    return keys[-1]


# --- the messages --------------------------------------------------------------------------

#: What a key of each pydantic type error takes.
EXPECTED = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "a whole number",
    "int_parsing": "a whole number",
    "int_from_float": "a whole number, written without a point",
    "int_parsing_size": "a whole number of at most 19 digits",
    "bool_type": "true or false",
    "bool_parsing": "true or false",
    "string_type": "text",
    "string_unicode": "text",
    "bytes_type": "text",
    "list_type": "a list",
    "tuple_type": "a list",
    "set_type": "a list",
    "dict_type": "a mapping of keys to values",
    "model_type": "a mapping of keys to values",
    "model_attributes_type": "a mapping of keys to values",
    "dataclass_type": "a mapping of keys to values",
    "path_type": "a file path",
    "none_required": "no value",
    "callable_type": "a function",
}
#: Numeric bounds: pydantic's type, its ``ctx`` key and the sentence.
BOUNDS = {
    "greater_than": ("gt", "must be more than"),
    "greater_than_equal": ("ge", "must be at least"),
    "less_than": ("lt", "must be less than"),
    "less_than_equal": ("le", "must be at most"),
    "multiple_of": ("multiple_of", "must be a multiple of"),
}
#: The patterns of text fields, said in words.
PATTERNS = {r"^[^/\s][^/]*$": "a name without '/' that does not start with a space"}
#: Prefixes of pydantic's messages for the errors a validator of suspopt raised.
_CUSTOM = ("Value error, ", "Assertion failed, ")


def _expected(kind: str, err: dict) -> str | None:
    """What the key takes for a type error (None for another error)."""
    return EXPECTED.get(kind)


def _quoted_number(err: dict) -> bool:
    """Whether a number's error is for a number written in quotes (``'2210'``: text)."""
    if not isinstance(err.get("input"), str) or not err["type"].startswith(("float", "int")):
        return False
    try:
        float(err["input"])
    except ValueError:
        return False
    return True


def _bound(err: dict, place: _Place) -> str:
    key, sentence = BOUNDS[err["type"]]
    limit = (err.get("ctx") or {}).get(key)
    unit = _unit(place.field)
    limit_text = number(limit) if isinstance(limit, (int, float)) else str(limit)
    message = f"{sentence} {limit_text}{f' {unit}' if unit else ''}{_got(err)}"
    hint = slip_hint(place.loc, err.get("input"))
    return message + (f"; {hint}" if hint else "")


def _lengths(err: dict) -> str:
    ctx = err.get("ctx") or {}
    kind = err["type"]
    noun = "character" if kind.startswith("string") else "item"
    if kind.endswith("too_short"):
        n = ctx.get("min_length")
        return f"needs at least {n} {noun}{'s' if n != 1 else ''} (got {ctx.get('actual_length')})"
    n = ctx.get("max_length")
    return f"takes at most {n} {noun}{'s' if n != 1 else ''} (got {ctx.get('actual_length')})"


def _message(err: dict, place: _Place, allowed: list[str]) -> str:
    """The plain message of one pydantic error at ``place``."""
    kind, msg, ctx = err["type"], str(err.get("msg", "")), err.get("ctx") or {}
    if msg.startswith(_CUSTOM):
        return msg.split(", ", 1)[1]
    if kind == "missing":
        return "required key is missing"
    if kind == "extra_forbidden":
        close = suggest(place.loc[-1], allowed)
        if close:
            return f"unknown key; did you mean {', '.join(close)}?"
        return "unknown key" + (f"; allowed: {', '.join(allowed)}" if allowed else "")
    if kind == "literal_error":
        return _unknown(_what(place.loc), err.get("input"), _choices(ctx.get("expected", "")))
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        options = _tags(place.field) or _choices(ctx.get("expected_tags", ""))
        if kind == "union_tag_not_found":
            return f"required key is missing; one of {', '.join(map(str, options))}"
        given = err["input"].get("kind") if isinstance(err.get("input"), dict) else ctx.get("tag")
        return _unknown(_what(place.loc), given, options)
    if kind == "damper_kind":
        given = err["input"].get("kind") if isinstance(err.get("input"), dict) else None
        options = ["passive", "semi_active"]
        return _unknown("damper kind", given, options, labels=["passive (the default)", options[1]])
    if kind in BOUNDS:
        return _bound(err, place)
    if kind == "finite_number":
        return f"must be a finite number{_got(err)}"
    if kind in ("too_short", "too_long", "string_too_short", "string_too_long"):
        return _lengths(err)
    if kind == "string_pattern_mismatch":
        pattern = ctx.get("pattern", "")
        return f"must be {PATTERNS.get(pattern, f'text of the form {pattern}')}{_got(err)}"
    expected = _expected(kind, err)
    if kind.startswith("int") and isinstance(err.get("input"), float):  # (2.0, 2.5, 1e5)
        return f"expected a whole number, written without a point (got {err['input']!r})"
    if expected and _quoted_number(err):
        return f"expected {expected} (got the text {shown(err['input'])}: write numbers without quotes)"
    if expected:
        return f"expected {expected}{_got(err)}"
    return f"is not a valid value{_got(err)}"


def _merged(group: list[tuple[dict, _Place]], allowed) -> str:
    """One message for the errors of every member of a union at one key."""
    expected, unknown = [], None
    for err, place in group:
        if err["type"] == "literal_error":
            options = _choices((err.get("ctx") or {}).get("expected", ""))
            expected.append("one of " + ", ".join(map(str, options)))
            if isinstance(err.get("input"), str):
                unknown = (err, place, options)
        else:
            expected.append(_expected(err["type"], err) or _message(err, place, allowed))
    if unknown is not None and len(expected) > 1:  # a word, none of those allowed
        err, place, options = unknown
        others = tuple(dict.fromkeys(e for e in expected if not e.startswith("one of ")))
        return _unknown(_what(place.loc), err["input"], options, others)
    return f"expected {' or '.join(dict.fromkeys(expected))}{_got(group[0][0])}"


def _allowed(raw_loc: tuple, root: type) -> list[str]:
    """The keys allowed where the unknown key at the pydantic location ``raw_loc`` stands
    (for "did you mean")."""
    return sorted(getattr(_section_at(root, raw_loc[:-1]), "model_fields", {}))


def _section_at(root: type, loc: tuple) -> Any:
    """The model of the section at the pydantic location ``loc`` (None if none)."""
    annotation = _unwrap(_place(root, loc).annotation)
    return annotation if _is_model(annotation) else None


def plain_errors(errors: Sequence[Any], root: type) -> list[tuple[tuple, str]]:
    """``[(key path, message), ...]`` of pydantic's ``errors`` of validating ``root`` (the
    Config), in their order, each key path once per distinct problem (module docstring)."""
    out: list[tuple[tuple, str]] = []
    unions: dict[tuple, list[tuple[dict, _Place]]] = {}
    for err in errors:
        raw = tuple(err["loc"])
        place = _place(root, raw)
        if err["type"] in ("union_tag_invalid", "union_tag_not_found", "damper_kind"):
            place.loc = place.loc + ("kind",)
        if place.member_at is not None and err["type"] not in ("union_tag_invalid",):
            key = (raw[: place.member_at], _place(root, raw[: place.member_at]).loc)
            if key not in unions:
                unions[key] = []
                out.append((key, ""))  # (its place in the order)
            unions[key].append((err, place))
            continue
        allowed = _allowed(raw, root) if err["type"] == "extra_forbidden" else []
        out.append((place.loc, _message(err, place, allowed)))
    result = []
    for loc, message in out:
        if message or loc not in unions:
            result.append((loc, message))
            continue
        result.extend(_union_messages(unions[loc], loc[1]))
    return result


def _union_messages(group: list[tuple[dict, _Place]], loc: tuple) -> list[tuple[tuple, str]]:
    """The messages of the errors of a union's members at ``loc``: those inside the member
    the value meant (the errors that lie deeper than the union's key), else one for all."""
    deeper = [(e, p) for e, p in group if len(p.loc) > len(loc)]
    if deeper:
        return [(p.loc, _message(e, p, [])) for e, p in deeper]
    if len(group) == 1:
        err, place = group[0]
        return [(place.loc, _message(err, place, []))]
    return [(loc, _merged(group, []))]
