"""
The node's /diagnostics status: the core's health status as a ``DiagnosticStatus``.

What the status says (level, message, grouped key/values) is built without ROS by
:mod:`baseball_collision.core.health` (its :class:`Tally`, :class:`Snapshot`,
:func:`take_snapshot` and :func:`silent_streams` are re-exported here); :func:`report` only
converts it.
"""

from typing import Mapping

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue

from ..core.health import (
    health_status, HealthStatus, Period, silent_streams, Snapshot, take_snapshot, Tally)

__all__ = ['Period', 'report', 'silent_streams', 'Snapshot', 'status_message',
           'take_snapshot', 'Tally']


def status_message(status: HealthStatus) -> DiagnosticStatus:
    """Return a health status as a DiagnosticStatus (the groups' key/values, in order)."""
    return DiagnosticStatus(
        level=bytes([int(status.level)]), name=status.name, message=status.message,
        hardware_id=status.hardware_id,
        values=[KeyValue(key=key, value=value) for key, value in status.values()])


def report(snapshot: Snapshot, problems: Mapping[str, str]) -> DiagnosticStatus:
    """
    Return the detector's status over the period ending at ``snapshot.now``.

    See :func:`baseball_collision.core.health.health_status` for the levels and keys.

    :param problems: why a silent stream may be silent ('' or missing: nothing known).
    """
    return status_message(health_status(snapshot, problems))
