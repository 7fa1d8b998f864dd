"""Compare JSON documents made by the package: exact integers and strings, floats to ULPs."""

import math
from typing import Any, List

REL_TOL = 1e-9
"""Relative tolerance for floats: far below any physical meaning, far above rounding noise."""


def differences(actual: Any, expected: Any, where: str = '') -> List[str]:
    """
    Return where two JSON-like values differ (empty when they agree).

    Integers (stamps in ns, counts), strings, booleans and None must be equal; floats agree
    within ``REL_TOL`` (relative, and absolute below 1): the last bits of a float may differ
    between machines and numpy builds, a nanosecond stamp or a count may not.
    """
    if isinstance(expected, dict) and isinstance(actual, dict):
        found = []
        for key in sorted(set(expected) | set(actual)):
            if key not in actual or key not in expected:
                side = 'expected' if key in expected else 'actual'
                found.append(f'{where}.{key}: only in {side}')
            else:
                found += differences(actual[key], expected[key], f'{where}.{key}')
        return found
    if isinstance(expected, list) and isinstance(actual, list):
        if len(actual) != len(expected):
            return [f'{where}: {len(actual)} items, expected {len(expected)}']
        found = []
        for index, (a, e) in enumerate(zip(actual, expected)):
            found += differences(a, e, f'{where}[{index}]')
        return found
    if isinstance(expected, float) and isinstance(actual, float) and not isinstance(
            expected, bool):
        if math.isclose(actual, expected, rel_tol=REL_TOL, abs_tol=REL_TOL):
            return []
        return [f'{where}: {actual!r} != {expected!r}']
    if type(actual) is not type(expected) or actual != expected:
        return [f'{where}: {actual!r} != {expected!r}']
    return []
