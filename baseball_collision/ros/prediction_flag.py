"""
The ``~/impact_predicted`` flag: when a prediction turns it on, and when the node withdraws it.

The flag is latched and published only when it changes (a Bool's CDR bytes). A prediction turns
it on unless a contact was solved in the same sample after the prediction was made, or the
watch holds it back (``PredictionWatch.raises``: a ball that paused and flushed its samples
after a withdrawal for its silence). The contact (``~/impact``), a state reset and
``prediction_horizon`` turned off turn it off; so does the node itself when no frame of the
detector will: once the prediction has passed (``PredictionWatch.passed``), checked after each
input sample taken, or once an input has been silent beyond ``stale_timeout``, checked after
each sample and every ``diagnostics_period``. The detector's prediction is left as it is.

:class:`PredictionFlag` is a mixin base of ``node.ImpactNode``: it uses the node's outputs,
lock, settings, detector, input tally and ``PredictionWatch`` (``_watch``).
"""

import math
import time
from typing import Any, Dict, Optional, Tuple

from .messages import FLAG_CDR
from ..core.detector import Prediction
from ..core.detector.predictor import kept_flight_span


class PredictionFlag:
    """Raise and withdraw ``~/impact_predicted`` (a mixin base of ``ImpactNode``)."""

    _predicting: bool  # the flag as last published
    _contact_ns: Optional[int]  # a contact solved in the add being taken (ns)
    _outputs: Dict[str, Any]
    _streams: Tuple[str, ...]

    def _raise_prediction(self, prediction: Prediction) -> None:
        """
        Turn the flag on for ``prediction`` (just published), unless it may not raise it.

        Not for one made before a contact solved in the same add (``_contact_ns``), nor where
        the watch holds it back (``PredictionWatch.raises``); else the watch follows its instant.
        Called under the node's lock.
        """
        contact = self._contact_ns  # (one made before a contact solved since: off)
        if (contact is None or prediction.made_at_ns >= contact) and self._watch.raises(
                prediction.stamp_ns, self.detector.config.max_gap):
            self._set_predicting(True)
            self._watch.instant_ns = prediction.stamp_ns

    def _set_predicting(self, predicting: bool) -> None:
        """Publish a change of ~/impact_predicted (latched)."""
        if predicting != self._predicting:
            self._predicting = predicting
            self._outputs['impact_predicted'].publish(FLAG_CDR[predicting])  # a Bool's bytes

    def _withdraw_a_passed_prediction(self, now: float) -> None:
        """
        Turn ``~/impact_predicted`` false once no input can still bring the predicted contact.

        Called under the node's lock after an input sample was taken, at ``now`` (s, the
        steady clock its arrival was counted on): when the prediction has passed
        (``PredictionWatch.passed``: every stream took two samples more than ``max_gap`` past
        the predicted instant without a contact, or the bat did and the ball has been silent
        longer than its lag behind the bat plus ``max_gap``, the bat streams past the span its
        flight holds unseen, ``kept_flight_span``; the detector's own frames clear a
        prediction only at its next frame that predicts), or when an input has been silent
        beyond ``stale_timeout`` (``_silent_locked``; checked here too, so a stream lost while
        another streams on ends it then, not up to a ``diagnostics_period`` later). The
        detector's prediction is left as it is.

        :param now: the steady-clock time (s) of the sample just taken.
        """
        config = self.detector.config
        if self._watch.passed(now, self.tally.last_arrival, config.max_gap,
                              kept_flight_span(config.prediction_window)) \
                or self._silent_locked(now):
            self._set_predicting(False)

    def _withdraw_a_silent_prediction(self) -> None:
        """
        Turn ``~/impact_predicted`` false once an input has been silent beyond ``stale_timeout``.

        A prediction is cleared by the frame that shows it wrong or past; when the frames stop
        (the tracker lost the ball, the streams died) none comes, and the flag stayed true for
        good: an arm waited on a contact that nothing will measure. Checked every
        ``diagnostics_period`` (all streams silent) and after each input sample (one silent,
        the others streaming: ``_withdraw_a_passed_prediction``). The detector's prediction is
        left as it is: its next prediction turns the flag true again.
        """
        with self._lock:
            if self._predicting and self._silent_locked(time.monotonic()):
                self._set_predicting(False)

    def _silent_locked(self, now: float) -> bool:
        """
        Return whether an input has been silent beyond ``stale_timeout`` at ``now``.

        :param now: the steady-clock time (s) to measure the silence to; the node's lock held.
        """
        timeout = self.settings['stale_timeout']
        return any(now - self.tally.last_arrival.get(stream, -math.inf) > timeout
                   for stream in self._streams)
