"""No widget of the app hides one of Qt's own methods behind an attribute of its own.

A ``QGroupBox`` that kept the main window as ``self.window`` made Qt's ``QWidget.window()`` a
``MainWindow``: the export dialog's ``parent.window()`` raised ``TypeError: 'MainWindow' object is
not callable`` after the CSV was written, and the app aborted (issue 54, defect 2). The check is
static: every ``self.<name> = ...`` in a ``QObject`` subclass of ``facetraj_app`` is looked up on its
Qt base class, so that the next such name fails here, not in a user's hands.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import textwrap

import pytest

pytest.importorskip("PyQt6")
from PyQt6.QtCore import QObject


def app_qobject_classes() -> list[type]:
    """Every ``QObject`` subclass defined in a module of ``facetraj_app``."""
    import facetraj_app

    found = []
    for info in pkgutil.walk_packages(facetraj_app.__path__, "facetraj_app."):
        module = importlib.import_module(info.name)
        for _name, cls in inspect.getmembers(module, inspect.isclass):
            if cls.__module__ == module.__name__ and issubclass(cls, QObject):
                found.append(cls)
    return found


def assigned_attributes(cls: type) -> set[str]:
    """The names ``cls``'s own code assigns as ``self.<name>`` (plain, annotated, augmented,
    tuple targets)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    names = set()
    for node in ast.walk(tree):
        targets = (node.targets if isinstance(node, ast.Assign)
                   else [node.target] if isinstance(node, (ast.AnnAssign, ast.AugAssign)) else [])
        for target in targets:
            for part in ast.walk(target):
                if isinstance(part, ast.Attribute) and isinstance(part.value, ast.Name) \
                        and part.value.id == "self":
                    names.add(part.attr)
    return names


def qt_base(cls: type) -> type:
    return next(b for b in cls.__mro__ if b.__module__.startswith("PyQt6"))


def test_the_check_finds_a_shadowed_method():
    """The check itself: the defect as it was is found."""
    from PyQt6.QtWidgets import QGroupBox

    class Run(QGroupBox):
        def __init__(self, window):
            super().__init__()
            self.measure, self.window = None, window

    assert {"window"} <= assigned_attributes(Run) and callable(qt_base(Run).window)


def test_no_widget_attribute_hides_a_qt_method():
    classes = app_qobject_classes()
    assert len(classes) > 40            # the app's widgets were found (a broken walk finds none)
    hidden = sorted(f"{cls.__module__}.{cls.__name__}.{name} hides {qt_base(cls).__name__}.{name}()"
                    for cls in classes for name in assigned_attributes(cls)
                    if callable(getattr(qt_base(cls), name, None)))
    assert not hidden, "\n".join(hidden)
