"""Analysis views (similarity matrix, metrics, PC modes, codebook inspector, errors, kinematics).

``install(window)`` adds them to the main window; see the window contract in ``app/main_window.py``.
"""


def install(window) -> None:
    """Add the analysis views to ``window`` (filled in by the analysis views work)."""
