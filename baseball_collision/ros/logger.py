"""
A node's log lines sent to rcutils without rclpy's per-call look-up of the caller's source.

rclpy's ``RcutilsLogger.log`` names the line's call site (function, file, line) for rcutils, the
same as this does, but finds it with ``inspect.getframeinfo`` on each frame from its own up to
the caller's, and that reads the source file's lines (``linecache``) every time: about 0.2 ms
a line on an idle machine (``benchmarks/bench_logger.py`` prints both against each other; about
1 ms on a loaded one, ``inputs.Throttle``), inside the executor callback that logs (a near
miss's message, an impact's completion). :class:`DirectLogger` reads the caller's code object
and line number from its frame (what rcutils is given; no file is opened) and hands the line to
the same rcutils call rclpy makes, so the line's text, severity, logger name, call site,
``/rosout`` record and the ``--log-level`` filter are those rclpy's own call gives. It keeps no
rclpy filters (``once``, ``skip_first``, ``throttle_duration_sec``): the node throttles before
it makes a line (``inputs.Throttle``).

rcutils' call is rclpy's extension's (``rclpy.impl.implementation_singleton``), as rclpy's logger
makes it. Where an rclpy lacks it, :class:`DirectLogger` logs through rclpy's own logger instead.
"""

import os
import sys
from typing import Any, Callable, Optional

from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.logging import get_logger, LoggingSeverity

_LOG: Optional[Callable[..., Any]] = getattr(rclpy_implementation, 'rclpy_logging_rcutils_log',
                                             None)


class DirectLogger:
    """
    A named rcutils logger whose lines name their call site from the calling frame.

    :param name: the logger's name (e.g. a node's ``get_logger().name``).
    """

    __slots__ = ('name', '_fallback')

    def __init__(self, name: str) -> None:
        self.name = name
        self._fallback = get_logger(name)

    def is_enabled_for(self, severity: LoggingSeverity) -> bool:
        """Return whether a line of ``severity`` would be logged (the logger's level)."""
        return self._fallback.is_enabled_for(severity)

    def log(self, message: str, severity: LoggingSeverity, depth: int = 1) -> bool:
        """
        Log ``message`` at ``severity``, its call site the frame ``depth`` calls up from here.

        :returns: False when the logger's level leaves it out, else True.
        """
        if _LOG is None:
            return self._fallback.log(message, severity)
        if not self._fallback.is_enabled_for(severity):
            return False
        frame = sys._getframe(depth)
        code = frame.f_code
        _LOG(severity, self.name, message, code.co_name, os.path.abspath(code.co_filename),
             frame.f_lineno)
        return True

    def debug(self, message: str) -> bool:
        """Log ``message`` at DEBUG (:meth:`log`)."""
        return self.log(message, LoggingSeverity.DEBUG, 2)

    def info(self, message: str) -> bool:
        """Log ``message`` at INFO (:meth:`log`)."""
        return self.log(message, LoggingSeverity.INFO, 2)

    def warning(self, message: str) -> bool:
        """Log ``message`` at WARN (:meth:`log`)."""
        return self.log(message, LoggingSeverity.WARN, 2)

    def error(self, message: str) -> bool:
        """Log ``message`` at ERROR (:meth:`log`)."""
        return self.log(message, LoggingSeverity.ERROR, 2)
