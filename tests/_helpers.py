"""Helpers shared by the tests and the tools (no pytest here: `tools/interrupt_audit.py` imports this file too).

Ctrl-C to a command: the one way every test (and the audit tool) starts the `freefloat` command as a child
process, waits until its work is under way, sends SIGINT and times the exit.

    p = start_cli(["simulate", "naveen_dual_arm", "--t-final", "1e6"], cwd)
    r = sigint_when(p, "simulated", delay=1.0)       # r.code (130), r.took (s from the signal to the exit), r.err
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass


def start_cli(args, cwd=None, merged: bool = False) -> subprocess.Popen:
    """`python -m freefloat.cli ARGS` as a child process with unbuffered output, both streams piped (`merged`: its
    stdout goes into the stderr pipe, for commands whose progress is printed on stdout), and the default SIGINT
    disposition (a process started from a background job inherits an ignored SIGINT, and Python keeps it)."""
    return subprocess.Popen(
        [sys.executable, "-m", "freefloat.cli", *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT if merged else subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


@dataclass
class Interrupted:
    """What `sigint_when` saw."""

    #: exit code (130 after a Ctrl-C that kept what was finished)
    code: int | None
    #: seconds from the signal to the exit (inf: killed after `exit_within`; None: no signal was sent)
    took: float | None
    #: everything the command wrote to stderr (with `merged`, its stdout too) and to stdout
    err: str
    out: str
    #: seconds from the start of the wait to the signal (None: no signal was sent)
    sent_after: float | None


def sigint_when(
    p: subprocess.Popen,
    marker: str | None = None,
    delay: float = 0.0,
    *,
    wait: float = 120.0,
    regex: bool = False,
    exit_within: float = 60.0,
    strict: bool = True,
) -> Interrupted:
    """Wait (generously: a loaded machine imports slowly) until `marker` shows on the command's stderr (its work is
    under way; a regular expression if `regex`; None: any output), wait `delay` seconds more, send SIGINT and time
    the exit. `strict`: AssertionError when the marker does not come within `wait` seconds or the command ends
    before the signal; otherwise the signal goes after `wait` seconds anyway, and a command that ended first is
    reported with `took=None`. The process is killed if it outlives `exit_within` seconds after the signal."""
    err: list[str] = []
    out: list[str] = []
    seen = threading.Event()
    found = (lambda s: re.search(marker, s) is not None) if regex else (lambda s: marker in s)

    def read(stream, sink, watch):
        for ch in iter(lambda: stream.read(1), ""):
            sink.append(ch)
            if watch and not seen.is_set() and (marker is None or found("".join(sink[-400:]))):
                seen.set()
        if watch:
            seen.set()  # the stream closed: the command ended

    readers = [threading.Thread(target=read, args=(p.stderr or p.stdout, err, True), daemon=True)]
    if p.stderr is not None and p.stdout is not None:
        readers.append(threading.Thread(target=read, args=(p.stdout, out, False), daemon=True))
    for th in readers:
        th.start()
    t0 = time.monotonic()
    try:
        if not seen.wait(wait) and strict:
            raise AssertionError(f"{marker!r} did not show within {wait} s: {''.join(err)[-2000:]}")
        time.sleep(delay)
        if p.poll() is not None:
            if strict:
                raise AssertionError(f"the command ended (exit {p.returncode}) before SIGINT: {''.join(err)[-2000:]}")
            for th in readers:
                th.join(2)
            return Interrupted(p.returncode, None, "".join(err), "".join(out), None)
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        try:
            p.wait(timeout=exit_within)
            took = time.monotonic() - sent
        except subprocess.TimeoutExpired:
            took = float("inf")
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    for th in readers:
        th.join(5)
    return Interrupted(p.returncode, took, "".join(err), "".join(out), sent - t0)


def cycles(graph: dict) -> list[set]:
    """The import cycles of a directed graph {node: iterable of the nodes it imports}: its strongly connected
    components with more than one node (Tarjan's algorithm, iterative, so a deep import chain cannot overflow the
    stack). Used by the import-direction tests of the Python package and of the Rust engine."""
    index: dict = {}
    low: dict = {}
    stack: list = []
    on_stack: set = set()
    out: list[set] = []
    for root in list(graph):
        if root in index:
            continue
        work = [(root, iter(graph.get(root, ())))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(graph.get(w, ()))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = set()
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.add(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(comp)
    return out
