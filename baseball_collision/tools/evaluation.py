"""
Compatibility: the names of the former ``tools/evaluation.py``, now in their own modules.

Import from :mod:`.accuracy` (``compare_pitch``, ``run_scenario``, ``summarize``,
``PitchResult``) and :mod:`.truth` (``prediction_errors``, ``LEADS_S``, the one matching rule
``match_pitch``) instead. This module goes once nothing imports it.
"""

from .accuracy import compare_pitch, PitchResult, run_scenario, summarize
from .truth import LEADS_S, prediction_errors

__all__ = ['compare_pitch', 'PitchResult', 'run_scenario', 'summarize', 'LEADS_S',
           'prediction_errors']
