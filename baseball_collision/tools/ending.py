"""
Ending a finished command's process without the interpreter's teardown, when nothing is lost.

At exit, after the ``atexit`` handlers and the standard streams' flush, the interpreter frees
every module and object one by one: 25-35 ms of an ``analyze`` process (numpy, rosbags, the
detector's modules; BENCHMARKS.md, "Start-up and teardown"), a seventh of a short bag's whole
run, paid on one core after the table is printed. :func:`end_process` does what the ordinary
exit does that anyone can see, then ends the process with ``os._exit``:

* it returns (the caller then exits the ordinary way) while a thread that is not a daemon is
  alive (the ordinary exit waits for it), or while a file is open for writing (its buffer
  would be flushed by the teardown's freeing of it; the package's outputs are closed and
  committed before a command returns: ``Outputs``, ``BagWriter``);
* it runs the ``atexit`` handlers, as the ordinary exit does next (multiprocessing's, which
  ends and joins any pool process left; ``weakref.finalize``'s, which removes a reader's
  scratch copy of a bag; logging's flush);
* it flushes standard output and standard error; if that fails (a closed pipe) it returns, and
  the ordinary exit reports it and sets its exit code as it always did.

Objects frozen out of the collector (``gc.freeze``: the console script's imports,
``entry_points``) are not looked at: nothing the package imports opens a file to write.
A pool process forked by ``multiprocessing`` already ends this way (``os._exit`` after its
task loop).
"""

import atexit
import gc
import io
import os
import sys
import threading

WRITABLE_TYPES = (io.FileIO, io.BufferedWriter, io.BufferedRandom, io.TextIOWrapper)
"""The file objects whose freeing at exit may write (flush or close) something."""


def open_for_writing() -> list:
    """
    Return the file objects (not frozen, not the standard streams) still open for writing.

    A file object that cannot say (detached, broken) counts as open.
    """
    standard = set()
    for stream in (sys.stdin, sys.stdout, sys.stderr, sys.__stdin__, sys.__stdout__,
                   sys.__stderr__):
        buffer = getattr(stream, 'buffer', None)  # (a text stream's bytes, and their file)
        standard.update(id(layer) for layer in (stream, buffer, getattr(buffer, 'raw', None))
                        if layer is not None)
    found = []
    for candidate in gc.get_objects():
        if type(candidate) not in WRITABLE_TYPES or id(candidate) in standard:
            continue
        try:
            if candidate.closed or not candidate.writable():
                continue
        except (ValueError, OSError):
            pass
        found.append(candidate)
    return found


def other_threads() -> list:
    """Return the live threads the ordinary exit would wait for (not daemons, not this one)."""
    return [thread for thread in threading.enumerate()
            if not thread.daemon and thread is not threading.main_thread()]


def end_process(code: int) -> int:
    """
    End this process now with exit code ``code``, if nothing would be lost; else return it.

    Call it from the main thread when the program is done (its outputs closed), as the last
    thing before the ordinary exit. See the module's docstring for what is checked and done.

    :param code: the exit code (0-255).
    :returns: ``code``, only when the process must end the ordinary way (``sys.exit(code)``).
    """
    run_handlers = getattr(atexit, '_run_exitfuncs', None)  # (CPython's; the interpreter's own)
    if (not isinstance(code, int) or run_handlers is None
            or threading.current_thread() is not threading.main_thread() or other_threads()
            or open_for_writing()):
        return code
    run_handlers()  # (they run once: the ordinary exit would not run them again)
    if other_threads() or open_for_writing():
        return code
    try:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:
                stream.flush()
    except (OSError, ValueError):
        return code
    os._exit(code)
