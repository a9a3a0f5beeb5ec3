"""The shapes of ``adapt:`` rules, in a scenario and in a rules file (JSON-schema dicts).

Data only, apart from the rules' logic (``adaptrules.py``): the file schema (``schema.py``)
embeds them and the rules' loader validates a rules file with them, so neither module
imports the other to reach them.
"""

from __future__ import annotations

from typing import Any

RULES: dict[str, Any] = {
    "type": "array",
    "items": {
        "type": "object",
        "additionalProperties": False,
        "required": ["when", "set"],
        "properties": {
            "when": {
                "type": "object",
                "minProperties": 1,
                "additionalProperties": {
                    "type": "object",
                    "additionalProperties": False,
                    "anyOf": [{"required": ["below"]}, {"required": ["above"]}],
                    "properties": {"below": {"type": "number"}, "above": {"type": "number"}},
                },
            },
            "set": {"type": "object", "minProperties": 1},
            "hold": {"type": "number", "minimum": 0},
            "dwell": {"type": "number", "minimum": 0},
            "label": {"type": "string"},
        },
    },
}

#: ``adapt:`` in a scenario: the rules, or the name of a rules file (``amsa-phys adapt -o``)
SCHEMA: dict[str, Any] = {**RULES, "type": ["array", "string"], "minLength": 1}

#: A rules file: ``adapt:`` and nothing else (its comments say where the rules came from).
FILE: dict[str, Any] = {
    "type": "object",
    "additionalProperties": False,
    "required": ["adapt"],
    "properties": {"adapt": RULES},
}
