"""Compare JSON documents made by the package: exact integers and strings, floats to ULPs."""

from datetime import datetime, timezone
import math
from typing import Any, List

REL_TOL = 1e-9
"""Relative tolerance for floats: far below any physical meaning, far above rounding noise."""

NEAR_MISS_PLACE_TOL = 1e-7
"""Absolute tolerance (m, s, fraction) of where and when a near miss came closest.

A near miss is the minimum of the gap, found by golden-section search: the gap is flat there,
so a last-bit difference in the paths (OpenBLAS picks other kernels on an AVX-512 machine)
flips a comparison of two equal gaps and moves the place by sqrt(rounding / curvature), about
1e-10 s and 1e-8 m. Its smallest gap itself is insensitive to first order (``REL_TOL``)."""

NEAR_MISS_STAMP_NS = 10
"""Nanoseconds a near miss's stamp may move for the same reason (measured: 1)."""

_NEAR_MISS_PLACE = ('time_s', 'gap_vector', 'ball_position', 'bat_fraction',
                    'distance_from_tip_m')

_SMALLEST_GAP_PLACE = ('min_gap_time_s', 'min_gap_vector', 'min_gap_fraction')
"""A truth file's place of a pitch's smallest gap (``sim.truth``): a minimum found by search,
as a near miss's (measured: 1.1e-9 m apart on an AMD EPYC against the bundled file)."""


def _utc_ns(text: str) -> int:
    """Return ``report.utc_text``'s text (``2023-11-14T22:13:20.250117442Z``) as ns."""
    seconds = datetime.strptime(text[:19], '%Y-%m-%dT%H:%M:%S').replace(tzinfo=timezone.utc)
    return int(seconds.timestamp()) * 1_000_000_000 + int(text[20:29])


def differences(actual: Any, expected: Any, where: str = '') -> List[str]:
    """
    Return where two JSON-like values differ (empty when they agree).

    Integers (stamps in ns, counts), strings, booleans and None must be equal; floats agree
    within ``REL_TOL`` (relative, and absolute below 1): the last bits of a float may differ
    between machines and numpy builds, a nanosecond stamp or a count may not. Where and when a
    near miss came closest (its stamp included), and where a truth file's pitch had its
    smallest gap, agree within ``NEAR_MISS_PLACE_TOL`` and ``NEAR_MISS_STAMP_NS`` instead: a
    flat minimum amplifies those last bits (a near miss's ``stamp_utc``, its stamp as text, too).
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
    key = where.rsplit('.', 1)[-1].split('[')[0]
    place = ('.near_misses[' in where and key in (*_NEAR_MISS_PLACE, 'stamp_ns')
             or key in _SMALLEST_GAP_PLACE)
    if isinstance(expected, float) and isinstance(actual, float) and not isinstance(
            expected, bool):
        tolerance = NEAR_MISS_PLACE_TOL if place else REL_TOL
        if math.isclose(actual, expected, rel_tol=REL_TOL, abs_tol=tolerance):
            return []
        return [f'{where}: {actual!r} != {expected!r}']
    if '.near_misses[' in where and key == 'stamp_utc' and isinstance(actual, str) and \
            isinstance(expected, str):  # its stamp_ns as text
        place, actual, expected = True, _utc_ns(actual), _utc_ns(expected)
    if place and type(actual) is int and type(expected) is int:
        return [] if abs(actual - expected) <= NEAR_MISS_STAMP_NS else [
            f'{where}: {actual!r} != {expected!r}']
    if type(actual) is not type(expected) or actual != expected:
        return [f'{where}: {actual!r} != {expected!r}']
    return []
