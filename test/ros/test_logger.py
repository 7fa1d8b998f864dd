"""The node's log lines: rcutils given the same call site, text and level as rclpy's logger."""

import os
import sys
from typing import Any, List, Tuple

from baseball_collision.ros import logger as logger_module
from baseball_collision.ros.logger import DirectLogger
import pytest
from rclpy.impl import rcutils_logger
from rclpy.logging import get_logger, LoggingSeverity, set_logger_level

Call = Tuple[Any, ...]


class _Recorded:
    """rclpy's extension with its rcutils log call recorded (everything else passed on)."""

    def __init__(self, extension: Any, calls: List[Call]) -> None:
        self._extension, self._calls = extension, calls

    def rclpy_logging_rcutils_log(self, *args: Any) -> None:
        self._calls.append(args)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._extension, name)


@pytest.fixture
def rcutils_calls(monkeypatch: pytest.MonkeyPatch) -> Tuple[List[Call], List[Call]]:
    """Record what rclpy's logger and :class:`DirectLogger` hand rcutils, not logging it."""
    by_rclpy: List[Call] = []
    direct: List[Call] = []
    monkeypatch.setattr(rcutils_logger, '_rclpy', _Recorded(rcutils_logger._rclpy, by_rclpy))
    monkeypatch.setattr(logger_module, '_LOG', lambda *args: direct.append(args))
    return by_rclpy, direct


def _both(name: str, severity: str, message: str) -> Tuple[int, int]:
    """Log ``message`` through rclpy's logger, then DirectLogger; return the two call lines."""
    line = sys._getframe().f_lineno
    getattr(get_logger(name), severity)(message)
    getattr(DirectLogger(name), severity)(message)
    return line + 1, line + 2


@pytest.mark.parametrize('severity', ['debug', 'info', 'warning', 'error'])
def test_rcutils_gets_what_rclpys_logger_gives_it(
        rcutils_calls: Tuple[List[Call], List[Call]], severity: str) -> None:
    """Severity, name, text, function and file as rclpy's; the line each call's own."""
    by_rclpy, direct = rcutils_calls
    name = f'test_logger_{severity}'
    set_logger_level(name, LoggingSeverity.DEBUG)
    rclpy_line, direct_line = _both(name, severity, 'a line: 1.0 m/s')
    assert len(by_rclpy) == 1 and len(direct) == 1
    (level, logged_name, text, function, path, line), = by_rclpy
    assert direct[0] == (level, logged_name, text, function, path, direct_line)
    assert (logged_name, text, function, line) == (name, 'a line: 1.0 m/s', '_both', rclpy_line)
    assert path == os.path.abspath(__file__)
    assert int(level) == int(getattr(LoggingSeverity, 'WARN' if severity == 'warning'
                                     else severity.upper()))


def test_a_line_below_the_loggers_level_is_not_logged(
        rcutils_calls: Tuple[List[Call], List[Call]]) -> None:
    """The logger's level filters as rclpy's: nothing reaches rcutils, and False."""
    _, direct = rcutils_calls
    set_logger_level('test_logger_level', LoggingSeverity.WARN)
    lines = DirectLogger('test_logger_level')
    assert lines.info('left out') is False and lines.debug('left out') is False
    assert not lines.is_enabled_for(LoggingSeverity.INFO)
    assert lines.warning('kept') is True
    assert [call[2] for call in direct] == ['kept']


def test_without_rcutils_call_it_logs_through_rclpys_logger(
        rcutils_calls: Tuple[List[Call], List[Call]], monkeypatch: pytest.MonkeyPatch) -> None:
    """An rclpy without the extension's call: the line goes through rclpy's own logger."""
    by_rclpy, direct = rcutils_calls
    monkeypatch.setattr(logger_module, '_LOG', None)
    set_logger_level('test_logger_fallback', LoggingSeverity.INFO)
    assert DirectLogger('test_logger_fallback').info('through rclpy') is True
    assert not direct and [call[2] for call in by_rclpy] == ['through rclpy']
