"""
The parameter files and the README's parameter table, held to the one table.

``config/impact_node.yaml`` lists every parameter at its default in the table's order, and
what its comments show (read-only sections, choices, ranges, units) agrees with the table;
``config/impact_node_points.yaml`` sets only parameters of the table, to values the node takes;
the README's table names parameters of the table with their defaults.
"""

import re
from typing import Dict, List, Tuple

from baseball_collision.core.detector import (
    DEFAULTS, PARAMETERS, ParameterSpec, SPECS, validate_parameters)
import pytest
from support import REPO_ROOT
import yaml

CONFIG = REPO_ROOT / 'config' / 'impact_node.yaml'
POINTS_CONFIG = REPO_ROOT / 'config' / 'impact_node_points.yaml'
README = REPO_ROOT / 'README.md'


def _parameters(path) -> Dict[str, object]:
    return yaml.safe_load(path.read_text())['/**']['ros__parameters']


def _commented_lines() -> List[Tuple[str, str, bool]]:
    """Return (name, comment, under a read-only heading) for each parameter line of the YAML."""
    lines, read_only = [], False
    for line in CONFIG.read_text().splitlines():
        heading = re.match(r'\s*# ----(.*)----', line)
        if heading:
            read_only = '(read-only)' in heading.group(1)
            continue
        entry = re.match(r'    (\w+):[^#]*(?:#(.*))?$', line)
        if entry:
            lines.append((entry.group(1), (entry.group(2) or '').strip(), read_only))
    return lines


def _mentions(text: str, word: str) -> bool:
    """Return whether ``word`` stands on its own in ``text`` (``m`` is not in ``m/s``)."""
    return re.search(rf'(?<![\w/^-]){re.escape(word)}(?![\w/^])', text) is not None


def test_yaml_lists_every_parameter_at_its_default_in_table_order() -> None:
    """Names in the table's order, nothing else; each value is the table's default."""
    loaded = _parameters(CONFIG)
    assert list(loaded) == [spec.name for spec in PARAMETERS]
    for spec in PARAMETERS:
        default = list(spec.default) if isinstance(spec.default, tuple) else spec.default
        assert loaded[spec.name] == pytest.approx(default), spec.name
        assert type(loaded[spec.name]) is type(default) or spec.name == 'tip_offset', spec.name
    checked, defaults = validate_parameters(loaded), validate_parameters({})  # the node takes it
    for name, value in checked.items():  # the file shows the defaults to 4 decimals
        assert value == (pytest.approx(defaults[name], rel=1e-12) if isinstance(value, float)
                         else defaults[name]), name


@pytest.mark.parametrize('spec', PARAMETERS, ids=lambda spec: spec.name)
def test_yaml_comment_agrees_with_the_table(spec: ParameterSpec) -> None:
    """Read-only as the table says; every choice, the unit and a shown range as the table's."""
    comments = {name: (comment, heading) for name, comment, heading in _commented_lines()}
    comment, under_read_only = comments[spec.name]
    assert comment, spec.name
    assert bool(spec.read_only) == (under_read_only or 'read-only' in comment), comment
    for choice in spec.choices:
        assert _mentions(comment, choice), (choice, comment)
    if spec.unit:
        assert _mentions(comment, spec.unit), (spec.unit, comment)
    for low, high in re.findall(r'(?<![\w.])(\d+)-(\d+)(?![\w.])', comment):
        assert spec.bounds is not None and (spec.bounds.low, spec.bounds.high) == (
            int(low), int(high)), comment


def test_points_yaml_sets_parameters_the_node_takes() -> None:
    """The knob + tip example names only parameters of the table, with values the node takes."""
    points = _parameters(POINTS_CONFIG)
    assert set(points) <= set(SPECS) and points['bat_input'] == 'points'
    checked = validate_parameters(points)
    for name, value in points.items():
        assert checked[name] == pytest.approx(value), name


def _readme_rows() -> List[Tuple[List[str], str]]:
    """Return (parameter names, default text) of each row of the README's parameter table."""
    text = README.read_text()
    table = text[text.index('| parameter | default | |'):]
    rows = []
    for line in table.splitlines()[2:]:
        if not line.startswith('|'):
            break
        cells = [cell.strip() for cell in line.strip('|').split('|')]
        rows.append((re.findall(r'`(\w+)`', cells[0]), cells[1]))
    return rows


def _shown(text: str) -> object:
    """Return a default as the README shows it: a number, or a (back-quoted) string."""
    text = text.strip().strip('`')
    if text == "''":
        return ''
    try:
        return float(text)
    except ValueError:
        return text


def test_readme_table_names_parameters_with_their_defaults() -> None:
    """Each row's parameters are in the table, with the table's defaults."""
    rows = _readme_rows()
    assert len(rows) >= 8
    for names, default in rows:
        assert names and set(names) <= set(SPECS), names
        if default == '34-inch wood bat':
            assert set(names) == {'bat_profile', 'bat_length', 'bat_radius'}
            assert DEFAULTS['bat_profile'] == () and DEFAULTS['bat_radius'] == 0.0
            continue
        shown = [_shown(part) for part in default.split(', ')]
        assert len(shown) == len(names), (names, default)
        for name, value in zip(names, shown):
            assert value == pytest.approx(DEFAULTS[name]) if isinstance(value, float) \
                else value == DEFAULTS[name], (name, value)
