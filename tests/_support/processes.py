"""Processes as Linux's ``/proc`` shows them, for the tests of child processes that must end with their parent."""

import pathlib


def proc_stat(pid):
    """``(state, parent pid, start time)`` of process ``pid`` from ``/proc/PID/stat``, or None if it is gone (the
    start time tells a reused pid apart)."""
    try:
        text = pathlib.Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return None
    fields = text[text.rindex(")") + 2:].split()
    return fields[0], int(fields[1]), int(fields[19])
