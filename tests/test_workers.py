"""The task runner (app/workers.py) with real threads: results arrive on the GUI thread, closing
cancels and waits, and a task that outlives the close is detached instead of being destroyed
while it runs (which aborts the process)."""

from __future__ import annotations

import threading

import pytest

pytest.importorskip("pytestqt")

from PyQt6.QtCore import QObject

from facetraj_app.workers import Gate, TaskRunner

pytestmark = pytest.mark.gui


def test_result_arrives_and_close_waits_for_a_cancelled_task(qtbot):
    owner = QObject()
    runner = TaskRunner(owner)
    results = []
    with qtbot.waitSignal(runner.finished, timeout=10_000):
        runner.run(lambda progress: 6 * 7, results.append, "answer")
    assert results == [42] and not runner.busy
    gate = Gate(is_open=False)      # closed: the task waits on it until cancelled
    task = runner.run(lambda progress: progress.wait_open(gate), results.append, "waiting")
    runner.close(timeout_ms=10_000)
    assert task.isFinished() and results == [42]
    assert runner.run(lambda progress: 1, results.append, "after close").isFinished() is False
    qtbot.wait(10)
    assert results == [42]      # nothing starts after close


def test_a_task_that_ignores_cancel_is_detached_not_destroyed(qtbot):
    owner = QObject()
    runner = TaskRunner(owner)
    release = threading.Event()
    failures: list[BaseException] = []
    runner.error_handler = failures.append
    # no progress calls, no partial results: nothing to notice the cancellation with
    task = runner.run(lambda progress: release.wait(30), None, "stubborn")
    runner.close(timeout_ms=50)
    assert task.isRunning() and task.parent() is None
    owner.deleteLater()             # the owner goes; the thread must survive it
    qtbot.wait(50)
    release.set()
    qtbot.waitUntil(task.isFinished, timeout=10_000)
    assert failures == []


def test_background_work_waits_while_foreground_work_runs(qtbot):
    """``foreground_idle``: closed while a foreground task runs (not for background ones); a
    background task waiting on it goes on once the foreground work is done."""
    owner = QObject()
    runner = TaskRunner(owner)
    release = threading.Event()
    order: list[str] = []

    def sweep(progress) -> None:
        progress.wait_open(runner.foreground_idle)
        order.append("background")

    runner.run(sweep, None, "sweep", background=True)
    qtbot.waitUntil(lambda: not runner.tasks, timeout=10_000)    # nothing in the foreground yet
    assert runner.foreground_idle.is_open and order == ["background"]
    runner.run(lambda progress: (release.wait(30), order.append("foreground")), None, "synthesis")
    assert not runner.foreground_idle.is_open
    waiting = runner.run(sweep, None, "sweep", background=True)
    qtbot.wait(100)
    assert order == ["background"] and runner.running(waiting)
    release.set()
    qtbot.waitUntil(lambda: not runner.tasks, timeout=10_000)
    assert order == ["background", "foreground", "background"]
    assert runner.foreground_idle.is_open
    runner.close()
