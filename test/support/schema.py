"""
A small JSON Schema validator: the subset the package's schema files use, and nothing else.

``jsonschema`` is not a dependency (it would be one for the tests only); the schema files in
``schema/`` use only the keywords below, and a keyword outside them is an error here (so a
schema cannot silently ask for a check this validator skips). ``$ref`` resolves ``#/...``
inside a file and ``other.schema.json#/...`` to a file beside it.
"""

import json
from pathlib import Path
from typing import Any, Dict, List, Mapping, Tuple

SCHEMA_DIR = Path(__file__).resolve().parents[2] / 'schema'
"""The package's schema files."""

ANNOTATIONS = {'$schema', '$id', '$defs', 'title', 'description'}
CHECKED = {'type', 'const', 'enum', 'required', 'properties', 'additionalProperties', 'items',
           'minItems', 'maxItems', 'oneOf', '$ref'}
TYPES = {
    'object': lambda v: isinstance(v, dict),
    'array': lambda v: isinstance(v, list),
    'string': lambda v: isinstance(v, str),
    'integer': lambda v: isinstance(v, int) and not isinstance(v, bool),
    'number': lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
    'boolean': lambda v: isinstance(v, bool),
    'null': lambda v: v is None,
}


def load_schema(name: str) -> Dict[str, Any]:
    """Return a schema file of ``schema/`` by name."""
    return json.loads((SCHEMA_DIR / name).read_text())


class Validator:
    """Check instances against a schema file of ``schema/`` (see the module for the subset)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._files: Dict[str, Dict[str, Any]] = {}

    def _file(self, name: str) -> Dict[str, Any]:
        if name not in self._files:
            self._files[name] = load_schema(name)
        return self._files[name]

    def _resolve(self, ref: str, base: str) -> Tuple[Mapping[str, Any], str]:
        name, _, pointer = ref.partition('#')
        name = name or base
        node: Any = self._file(name)
        for part in [p for p in pointer.split('/') if p]:
            node = node[part]
        return node, name

    def errors(self, instance: Any, pointer: str = '') -> List[str]:
        """Return every place ``instance`` breaks the schema (empty: valid)."""
        schema, base = self._resolve(pointer or '#', self.name)
        return self._check(instance, schema, base, '$')

    def _check(self, value: Any, schema: Mapping[str, Any], base: str, where: str) -> List[str]:
        unknown = set(schema) - ANNOTATIONS - CHECKED
        if unknown:
            raise ValueError(f'{base}: keywords not supported here: {sorted(unknown)}')
        found: List[str] = []
        if '$ref' in schema:
            target, target_base = self._resolve(schema['$ref'], base)
            found += self._check(value, target, target_base, where)
        if 'type' in schema:
            names = schema['type'] if isinstance(schema['type'], list) else [schema['type']]
            if not any(TYPES[name](value) for name in names):
                return found + [f'{where}: {value!r} is not of type {names}']
        if 'const' in schema and value != schema['const']:
            found.append(f'{where}: {value!r} is not {schema["const"]!r}')
        if 'enum' in schema and value not in schema['enum']:
            found.append(f'{where}: {value!r} is not one of {schema["enum"]}')
        if 'oneOf' in schema:
            passing = [option for option in schema['oneOf']
                       if not self._check(value, option, base, where)]
            if len(passing) != 1:
                found.append(f'{where}: matches {len(passing)} of the oneOf schemas, not 1')
        if isinstance(value, dict):
            found += self._object(value, schema, base, where)
        if isinstance(value, list):
            if len(value) < schema.get('minItems', 0):
                found.append(f'{where}: fewer than {schema["minItems"]} items')
            if 'maxItems' in schema and len(value) > schema['maxItems']:
                found.append(f'{where}: more than {schema["maxItems"]} items')
            if 'items' in schema:
                for index, item in enumerate(value):
                    found += self._check(item, schema['items'], base, f'{where}[{index}]')
        return found

    def _object(self, value: Mapping[str, Any], schema: Mapping[str, Any], base: str,
                where: str) -> List[str]:
        found = [f'{where}: missing {key!r}' for key in schema.get('required', ())
                 if key not in value]
        properties = schema.get('properties', {})
        extra = schema.get('additionalProperties', True)
        for key, item in value.items():
            if key in properties:
                found += self._check(item, properties[key], base, f'{where}.{key}')
            elif extra is False:
                found.append(f'{where}: unexpected key {key!r}')
            elif isinstance(extra, dict):
                found += self._check(item, extra, base, f'{where}.{key}')
        return found
