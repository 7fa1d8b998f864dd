"""
Compatibility: the names of the former ``tools/analysis.py``, now in their own modules.

Import from the modules instead: :mod:`.analyze` (``analyze_bag``, ``AnalysisOptions``,
``BagAnalysis``), :mod:`.report` (table, JSON, CSV), :mod:`.plots`, :mod:`.truth` (truth files
and matching), :mod:`.outputs` (``Outputs``), :mod:`.parameters` (``load_parameters``,
``build_config``, ``NODE_NAME``, ``output_topics``). This module goes once nothing imports it.
"""

from .analyze import AnalysisOptions, analyze_bag, BagAnalysis, PROGRESS_MIN_MESSAGES
from .outputs import Outputs
from .parameters import build_config, load_parameters, NODE_NAME, OFFLINE_MODEL, output_topics
from .plots import plot_names, PLOT_WINDOW_S, write_plots
from .report import (
    CSV_COLUMNS, csv_text, format_report, JSON_FORMAT, prediction_lines, summary_line,
    TABLE_COLUMNS, to_json, truth_line, write_json)
from .truth import (
    BAG_SUFFIXES, compare_truth, EventLike, ImpactLike, load_truth, TRUTH_FORMAT, truth_path,
    TruthComparison)

__all__ = [
    'AnalysisOptions', 'analyze_bag', 'BagAnalysis', 'PROGRESS_MIN_MESSAGES', 'Outputs',
    'build_config', 'load_parameters', 'NODE_NAME', 'OFFLINE_MODEL', 'output_topics',
    'plot_names', 'PLOT_WINDOW_S', 'write_plots', 'CSV_COLUMNS', 'csv_text', 'format_report',
    'JSON_FORMAT', 'prediction_lines', 'summary_line', 'TABLE_COLUMNS', 'to_json', 'truth_line',
    'write_json', 'BAG_SUFFIXES', 'compare_truth', 'EventLike', 'ImpactLike', 'load_truth',
    'TRUTH_FORMAT', 'truth_path', 'TruthComparison',
]
