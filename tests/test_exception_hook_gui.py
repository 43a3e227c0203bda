"""An unexpected exception in a slot never ends the app (issue 54): with the app's exception hook
(``app/exception_hook.py``, installed by ``run_app``) the failure is shown in a dialog that says
what the user did, logged with its traceback, and the window goes on; with Python's own hook PyQt6
aborts the process (the check that this test can fail). Each run is a child process
(tests/hook_child.py): the abort must not take pytest with it."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import DEFAULT_CORPUS

if not os.environ.get("DISPLAY"):
    pytest.skip("the app tests need an X display (run under xvfb-run)", allow_module_level=True)

pytestmark = pytest.mark.gui
CHILD = Path(__file__).with_name("hook_child.py")


def run_child(mode: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(CHILD.parent)}
    return subprocess.run([sys.executable, str(CHILD), str(DEFAULT_CORPUS), mode], env=env,
                          capture_output=True, text=True, timeout=600)


def test_a_failing_slot_is_a_dialog_and_the_window_goes_on(trained_cache):
    run = run_child("hook")
    assert run.returncode == 0, run.stderr[-3000:]
    dialogs = [ln for ln in run.stdout.splitlines() if ln.startswith("DIALOG: ")]
    assert dialogs == ['DIALOG: internal error after key "Right": RuntimeError: injected failure '
                       'in a slot (the window keeps running; the traceback is in the log)']
    assert "Traceback" in run.stderr and "injected failure in a slot" in run.stderr
    alive = [ln for ln in run.stdout.splitlines() if ln.startswith("ALIVE at ")]
    assert alive, run.stdout
    at, duration = (float(x) for x in alive[0].split()[2::3][:2])
    assert at == pytest.approx(duration, abs=0.02)       # End worked after the failure


def test_without_the_hook_pyqt_aborts(trained_cache):
    run = run_child("bare")
    assert run.returncode != 0
    assert "ALIVE" not in run.stdout
