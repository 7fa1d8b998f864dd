"""
The detector's health as plain data: counters in, a status (level, message, grouped values) out.

Pure Python (no ROS), in three parts with one job each:

* ``gaps``: messages lost on an input, from its stamps (:class:`StampGaps`) and its
  publishers' sequence numbers (:class:`PublisherGaps`);
* ``tally``: what the node counts (:class:`Tally`, and a diagnostics :class:`Period`);
* ``status``: the status over a period (:func:`take_snapshot`, :func:`health_status`).

The node counts what arrives in a :class:`Tally`; once a period it copies the tally and the
detector's counters into a :class:`Snapshot` and :func:`health_status` turns them into a
:class:`HealthStatus`; ``ros.diagnostics`` converts that into a
``diagnostic_msgs/DiagnosticStatus``, and ``analyze --out-bag`` writes the same statuses into
``/diagnostics`` of its bag. Times are seconds on any monotonic clock passed in (wall time in
the node, the bag's log time offline); why a silent topic is silent (no publisher discovered
yet, another type) is asked of the ROS graph by the node for the streams
:func:`silent_streams` names.
"""

from .gaps import (
    LOSS_FACTOR, LOSS_GAP_MAX_NS, OTHER_PUBLISHER_NS, PublisherGaps, StampGaps)
from .status import (
    format_stamp, HARDWARE_ID, health_status, HealthStatus, Level, NS_PER_S, RESETS_ERROR,
    silent_streams, Snapshot, take_snapshot, Values)
from .tally import Period, Tally

__all__ = ['format_stamp', 'HARDWARE_ID', 'health_status', 'HealthStatus', 'Level',
           'LOSS_FACTOR', 'LOSS_GAP_MAX_NS', 'NS_PER_S', 'OTHER_PUBLISHER_NS', 'Period',
           'PublisherGaps', 'RESETS_ERROR', 'silent_streams', 'Snapshot', 'StampGaps',
           'take_snapshot', 'Tally', 'Values']
