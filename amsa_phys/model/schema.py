"""The shapes of a world and a scenario, checked with jsonschema.

jsonschema (rather than pydantic or a hand-written walker) because the shape is data we can
print and test, its errors carry the exact key path, and we already keep a line for every key
path: an error becomes ``file:line: key.path: message`` with no guessing. Values (ranges,
parameter names, links) are judged afterwards by the world and scenario builders.
"""

from __future__ import annotations

import importlib
import math
import sys
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from .params import digits_text, number_text_hint, short_repr, yaml_type
from .rates import MAX_RATE_HZ, MIN_PHYSICS_RATE_HZ, MIN_RATE_HZ
from .ruleshapes import FILE as RULES_FILE
from .ruleshapes import SCHEMA as ADAPT
from .suggest import did_you_mean
from .yamlio import KeyPath, YamlDoc

if TYPE_CHECKING:  # imported only to word an error: ~50-100 ms of imports off the run path
    import jsonschema

NAME = r"^[A-Za-z_][A-Za-z0-9_]*$"
#: The largest seed: numpy's seed tree takes any non-negative integer, files stay int64.
MAX_SEED = 2**63 - 1
#: The longest run, in seconds of simulated time: 10^6 s (11.6 days, 2,000 times the paper's
#: 500 s scenarios). Hostile input must be bounded in time: ``duration: 1e308`` (or
#: ``--duration 1e308``) was legal and ran until it was stopped. The MDE world runs ~500x
#: real time, so the longest run of it takes about half an hour. The file's ``duration:``
#: and every ``--duration`` (run, sweep, falsify, ``ap.run``) are held to it.
MAX_DURATION_S = 1_000_000


def duration_problem(duration: Fraction) -> str | None:
    """Why ``duration`` (seconds, exact) cannot be a run's length (None if it can)."""
    if duration <= 0:
        return f"must be > 0, got {float(duration):g}"
    if duration > MAX_DURATION_S:
        return (
            f"must be at most {MAX_DURATION_S:,} s of simulated time "
            f"({MAX_DURATION_S / 86_400:.1f} days, the limit on a run's length), "
            f"got {float(duration):g}"
        )
    return None


#: A Data name: a NAME, or ``Composite.NAME`` for a Data declared inside a Composite.
DATA_NAME = r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$"
_num = {"type": "number"}
_pos = {"type": "number", "exclusiveMinimum": 0}
#: A component's rate and the trace's: what the engine can schedule in reasonable time
#: (1e9 Hz would be 1e9 instants per simulated second; 1e-9 Hz a schedule that repeats
#: every 30 years). ``model/rates.py`` checks that the rates together repeat soon enough.
_rate = {"type": "number", "minimum": MIN_RATE_HZ, "maximum": MAX_RATE_HZ, "description": "rate"}
_physics_rate = {
    "type": "number",
    "minimum": MIN_PHYSICS_RATE_HZ,
    "maximum": MAX_RATE_HZ,
    "description": "rate",
}
_nonneg = {"type": "number", "minimum": 0}
_point = {"type": "array", "items": _num, "minItems": 2, "maxItems": 2}
#: A time: seconds as a number, or an exact fraction "7/3" (an instant of a 3 Hz component,
#: which no decimal writes exactly; the resolved scenario writes such instants this way).
FRACTION = r"^[0-9]+/[1-9][0-9]*$"
_time = {"anyOf": [_pos, {"type": "string", "pattern": FRACTION}]}

OBSTACLE = {
    "type": "object",
    "required": ["type"],
    "properties": {"type": {"enum": ["box", "circle", "polyline"]}},
    "allOf": [
        {
            "if": {"properties": {"type": {"const": "box"}}},
            "then": {
                "additionalProperties": False,
                "required": ["x", "y", "width", "height"],
                "properties": {
                    "type": {},
                    "x": _num,
                    "y": _num,
                    "width": _pos,
                    "height": _pos,
                    "angle": _num,
                },
            },
        },
        {
            "if": {"properties": {"type": {"const": "circle"}}},
            "then": {
                "additionalProperties": False,
                "required": ["x", "y", "radius"],
                "properties": {"type": {}, "x": _num, "y": _num, "radius": _pos},
            },
        },
        {
            "if": {"properties": {"type": {"const": "polyline"}}},
            "then": {
                "additionalProperties": False,
                "required": ["points"],
                "properties": {
                    "type": {},
                    "points": {"type": "array", "items": _point, "minItems": 2},
                    "thickness": _pos,
                },
            },
        },
    ],
}

PHYSICS = {
    "type": "object",
    "additionalProperties": False,
    "properties": {
        "rate": _physics_rate,
        "gravity": _pos,
        "ground": {
            "type": "object",
            "additionalProperties": False,
            "properties": {"friction": _nonneg, "rolling_resistance": _nonneg},
        },
        "walls": {
            "type": "object",
            "additionalProperties": False,
            "required": ["xmin", "xmax", "ymin", "ymax"],
            "properties": {"xmin": _num, "xmax": _num, "ymin": _num, "ymax": _num},
        },
        "obstacles": {"type": "array", "items": OBSTACLE},
        "max_speed": _pos,
        "extent": _pos,
    },
}

WORLD: dict[str, Any] = {
    "type": "object",
    "additionalProperties": False,
    "required": ["components"],
    "properties": {
        "name": {"type": "string"},
        "description": {"type": "string"},
        "physics": PHYSICS,
        "components": {"$ref": "#/$defs/components"},
        "schedule": {"type": "array", "items": {"type": "string"}, "uniqueItems": True},
        "timing": {
            "type": "object",
            "additionalProperties": False,
            "properties": {
                "free_running": {"type": "boolean"},
                "resolution": {"type": "number", "minimum": 0.000001, "maximum": 1},
            },
        },
        "data": {
            "type": "object",
            "propertyNames": {"pattern": DATA_NAME},
            "additionalProperties": {"type": "string"},
        },
    },
    "$defs": {
        "components": {
            "type": "object",
            "minProperties": 1,
            "propertyNames": {"pattern": NAME},
            "additionalProperties": {"$ref": "#/$defs/component"},
        },
        "component": {
            "type": "object",
            "if": {"required": ["components"]},
            "then": {"$ref": "#/$defs/composite"},
            "else": {"$ref": "#/$defs/leaf"},
        },
        "composite": {
            "additionalProperties": False,
            "properties": {
                "components": {"$ref": "#/$defs/components"},
                "description": {"type": "string"},
                "count": {"type": "integer", "minimum": 1, "maximum": 10000},
                "schedule": {"type": "array", "items": {"type": "string"}, "uniqueItems": True},
                "first": {
                    "type": "object",
                    "additionalProperties": {
                        "type": "object",
                        "additionalProperties": False,
                        "properties": {
                            "inputs": {
                                "type": "object",
                                "additionalProperties": {"type": "string"},
                            }
                        },
                    },
                },
            },
        },
        "leaf": {
            "additionalProperties": False,
            "required": ["template"],
            "properties": {
                "template": {"type": "string", "minLength": 1},
                "freq": _rate,
                # loop timing (model/timing.py judges the values and words the errors)
                "latency": {"type": ["number", "string"]},
                "jitter": {"type": ["number", "string"]},
                "phase": {"type": ["number", "string"]},
                "params": {"type": "object"},
                "inputs": {"type": "object", "additionalProperties": {"type": "string"}},
                "description": {"type": "string"},
            },
        },
    },
}

SCENARIO: dict[str, Any] = {
    "type": "object",
    "additionalProperties": False,
    "required": ["world", "duration"],
    "properties": {
        "name": {"type": "string"},
        "description": {"type": "string"},
        "world": {"type": ["string", "object"]},
        "duration": _time,
        "seed": {"type": "integer", "minimum": 0, "maximum": MAX_SEED},
        "log_rate": _rate,
        "trace_columns": {
            "type": ["array", "string"],
            "minItems": 1,
            "minLength": 1,
            "items": {"type": "string", "minLength": 1},
        },
        "quality": {
            "type": "object",
            "additionalProperties": False,
            "required": ["signal", "reference"],
            "properties": {
                "signal": {"type": "string"},
                "reference": _num,
                "tolerance": _pos,
                "dwell": _nonneg,
            },
        },
        "physics": PHYSICS,  # merged over the world's (model/scenario.py: with_physics)
        "set": {"type": "object"},
        "timeline": {
            "type": "array",
            "items": {
                "type": "object",
                "additionalProperties": False,
                "required": ["at", "set"],
                "properties": {
                    "at": _time,
                    "set": {"type": "object", "minProperties": 1},
                    "label": {"type": "string"},
                    "new_phase": {"type": "boolean"},
                },
            },
        },
        "adapt": ADAPT,  # reconfiguration rules (model/adaptrules.py)
        # Leaves stepped by a user's ROS 2 nodes (ros/external.py)
        "ros2": {
            "type": ["array", "string"],
            "minItems": 1,
            "minLength": 1,
            "items": {"type": "string", "minLength": 1},
        },
        "ros2_timeout": {"type": "number", "exclusiveMinimum": 0, "maximum": 3600},
        "sweep": {
            "type": "object",
            "additionalProperties": False,
            "properties": {
                "grid": {
                    "type": "object",
                    "additionalProperties": {"type": "array", "minItems": 1},
                },
                "contexts": {"type": "object", "additionalProperties": {"type": "object"}},
                "seeds": {"type": "integer", "minimum": 1},
                "metric": {"type": "string"},
            },
        },
        "expect": {
            "type": "array",
            "items": {
                "type": "object",
                "additionalProperties": False,
                "anyOf": [
                    {"required": ["below"]},
                    {"required": ["above"]},
                    {"required": ["stl"]},
                ],
                "properties": {
                    "stl": {"type": "string", "minLength": 1},
                    "name": {"type": "string"},
                    "metric": {"type": "string"},
                    "trace": {"type": "string"},
                    "phase": {"type": "integer", "minimum": 0},
                    "after": _nonneg,
                    "before": _pos,
                    "below": _num,
                    "above": _num,
                },
            },
        },
    },
}

_FLOAT_MAX = int(sys.float_info.max)

_TYPE_WORDS = {
    "object": "a mapping",
    "array": "a list",
    "string": "a string",
    "number": "a number",
    "integer": "an integer",
    "boolean": "true or false",
}


def validate(
    data: Any, schema: dict[str, Any], doc: YamlDoc, prefix: KeyPath = (), quote: bool = True
) -> None:
    """Raise the ConfigError of the first shape error (by line), or return. ``quote=False``:
    a file another names (``world:``, ``adapt:``), maybe any YAML file of the machine, whose
    refusal names keys (what a typo needs) and a wrong value's kind, never the value."""
    bad = _first_nonfinite(data, prefix)
    if bad is not None:
        value = doc_value(data, bad[len(prefix) :])
        if isinstance(value, int):
            raise doc.error(bad, f"number too large ({too_large(value)})")
        raise doc.error(bad, "expected a finite number, got NaN or infinity")
    if _precompiled_accepts(data, schema):
        return
    import jsonschema  # the judge and the words of every refusal (model/shapegen.py)

    validator = jsonschema.Draft202012Validator(schema)
    errors = list(validator.iter_errors(data))
    if not errors:
        return
    located = [_locate(err, prefix, quote) for err in _leaves(errors)]
    keypath, message = min(located, key=lambda km: (doc.line(km[0]) or 0, -len(km[0])))
    raise doc.error(keypath, message)


def _precompiled_accepts(data: Any, schema: dict[str, Any]) -> bool:
    """True when the generated check of ``schema`` (``model/shapes``) accepts ``data``.

    False for a rejected file and for a schema without a generated check: jsonschema then
    decides and words the error, so this can only make a valid file cheaper.
    """
    name = _SHAPE_NAMES.get(id(schema))
    if name is None:
        return False
    check = importlib.import_module(f".shapes.{name}", __package__).validate
    try:
        check(data)
    except ValueError:  # fastjsonschema's JsonSchemaValueException
        return False
    return True


def _leaves(errors: list[jsonschema.ValidationError]) -> list[jsonschema.ValidationError]:
    """Flatten if/then/anyOf wrappers to the errors that say what is wrong."""
    out: list[jsonschema.ValidationError] = []
    for err in errors:
        if err.validator in ("allOf", "$ref", "if", "then", "else") and err.context:
            out.extend(_leaves(list(err.context)))
        else:
            out.append(err)
    return out


def _locate(
    err: jsonschema.ValidationError, prefix: KeyPath, quote: bool = True
) -> tuple[KeyPath, str]:
    path = (*prefix, *err.absolute_path)
    inst = err.instance
    kind = err.validator

    def shown(value: Any) -> str:  # " 'x'", or nothing where the file's values stay unsaid
        return f" {short_repr(value)}" if quote else ""

    if kind == "additionalProperties" and isinstance(inst, dict):
        known = list(err.schema.get("properties", {}))
        extra = [k for k in inst if k not in known]
        key = extra[0] if extra else "?"
        if not path and "world" in extra and "components" not in inst and "components" in known:
            # a scenario where a world is wanted (``graph``, ``export amsa``, a world: naming a
            # scenario): say which is which, as the reverse case does
            named = inst["world"] if isinstance(inst["world"], str) else "its world"
            return ("world",), (
                "this is a scenario file (it names its world: here); a world file is expected "
                f"— give the world it names ({short_repr(named)}) instead"
            )
        hint = did_you_mean(str(key), known) or (
            f"; expected one of: {', '.join(known)}" if known else ""
        )
        return (*path, key), f"unknown key{hint}"
    if kind == "required":
        missing = err.message.split("'")[1] if "'" in err.message else err.message
        if isinstance(inst, dict):  # ``durration:`` beside a missing ``duration``: say so there
            known = set(err.schema.get("properties", {}))
            for key in inst:
                if str(key) not in known and did_you_mean(str(key), [missing]):
                    return (*path, key), f"unknown key (did you mean {missing}?)"
        if not path and missing == "world" and isinstance(inst, dict) and "components" in inst:
            # a world file where a scenario is wanted (``run worlds/x.yaml``): say which is which
            return path, (
                "missing required key 'world': this is a world file (it has 'components'); "
                "a scenario names it (world: FILE) — see scenarios/*.yaml"
            )
        return path, f"missing required key '{missing}'"
    if kind == "type":
        want = err.validator_value
        wants = want if isinstance(want, list) else [want]
        words = " or ".join(_TYPE_WORDS.get(w, w) for w in wants)
        if not path:  # the whole file: say what it is, never echo what it holds
            return path, f"expected {words}, got {yaml_type(inst)}: not a world or scenario file"
        hint = number_text_hint(inst) if {"number", "integer"} & set(wants) and quote else ""
        return path, f"expected {words}, got {yaml_type(inst)}{shown(inst)}{hint}"
    if kind in ("minimum", "maximum") and err.schema.get("description") == "rate":
        lo, hi = err.schema["minimum"], err.schema["maximum"]
        if inst <= 0:
            return path, "must be > 0" + (f", got {inst}" if quote else "")
        said = f"{inst:g} Hz " if quote else ""
        return path, f"{said}is outside the rates amsa-phys runs ({lo:g} to {hi:g} Hz)"
    if kind in ("exclusiveMinimum", "minimum", "maximum"):
        sign = {"exclusiveMinimum": ">", "minimum": ">=", "maximum": "<="}[kind]
        return path, f"must be {sign} {err.validator_value}" + (f", got {inst}" if quote else "")
    if kind in ("enum", "const"):
        allowed = err.validator_value if kind == "enum" else [err.validator_value]
        got = short_repr(inst) if quote else yaml_type(inst)
        return path, f"expected one of {', '.join(map(str, allowed))}, got {got}"
    if kind == "pattern":
        if "propertyNames" in err.schema_path:  # a bad key: point at the key itself
            path = (*path, inst)
        return path, (
            f"{inst!r} is not a valid name (letters, digits and _, not starting with a digit)"
        )
    if kind == "anyOf" and err.validator_value == _time["anyOf"]:
        if isinstance(inst, int | float) and not isinstance(inst, bool):
            return path, "must be > 0" + (f", got {inst}" if quote else "")
        hint = number_text_hint(inst) if quote else ""
        return path, (
            'expected a positive number of seconds or an exact fraction such as "7/3", '
            f"got {yaml_type(inst)}{shown(inst)}{hint}"
        )
    if kind == "anyOf" and isinstance(inst, dict):
        return path, "needs 'below' or 'above'"
    if kind == "minProperties":
        return path, "must not be empty"
    if kind in ("minItems", "maxItems"):
        return path, f"wrong number of items ({err.message})"
    if kind == "uniqueItems":
        return path, "has repeated entries"
    return path, err.message


def too_large(value: int) -> str:
    """Why an integer is refused as a number: ``401 digits; a number must fit a float``."""
    return f"{digits_text(value)}; a number must fit a float, at most about 1.8e308"


def doc_value(data: Any, keypath: KeyPath) -> Any:
    """The value at ``keypath`` in ``data``."""
    for part in keypath:
        data = data[part]
    return data


def _first_nonfinite(data: Any, path: KeyPath) -> KeyPath | None:
    """The first NaN, infinity or integer too large for a float (401 digits) in ``data``."""
    if isinstance(data, float) and not math.isfinite(data):
        return path
    if isinstance(data, int) and not isinstance(data, bool) and abs(data) > _FLOAT_MAX:
        return path
    if isinstance(data, dict):
        for k, v in data.items():
            found = _first_nonfinite(v, (*path, k))
            if found is not None:
                return found
    if isinstance(data, list):
        for i, v in enumerate(data):
            found = _first_nonfinite(v, (*path, i))
            if found is not None:
                return found
    return None


def _shape_names() -> dict[int, str]:
    return {
        id(WORLD): "world",
        id(SCENARIO): "scenario",
        id(PHYSICS): "physics",
        id(RULES_FILE): "rules",
    }


#: id of a schema -> its generated check (``python -m amsa_phys.model.shapegen``)
_SHAPE_NAMES = _shape_names()
