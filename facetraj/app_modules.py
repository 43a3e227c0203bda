"""The commands that need the app (``gui``, ``video``, the Live window, the report's figures):
the app's modules imported here, in one place, with one line saying how to install it when the
app distribution is not installed (the engine distribution alone has ``train``, ``synth``,
``eval``, ``sweep``, ``similarity``, ``align``, ``corpus``, ``report`` and ``live --from-file``)."""

from __future__ import annotations

import importlib
from types import ModuleType

from facetraj_engine.errors import FacetrajError

#: the app's distribution, as pip installs it
APP_DISTRIBUTION = "facetraj"


class AppMissing(FacetrajError):
    """The app distribution is not installed (or a library it needs is missing)."""


def app_module(module: str, what: str) -> ModuleType:
    """``facetraj_app.<module>``, imported for ``what`` (``"facetraj gui"``); a missing app, or a
    library of its that is missing or cannot load (Qt without its system libraries), is one line
    saying so and how to install it."""
    try:
        return importlib.import_module(f"facetraj_app.{module}")
    except ModuleNotFoundError as exc:
        if (exc.name or "").split(".")[0] == "facetraj_app":
            raise AppMissing(f"{what} needs the app, which is not installed: pip install "
                             f"{APP_DISTRIBUTION}") from exc
        raise AppMissing(f"{what} needs the app, which cannot start ({exc}): pip install "
                         f"{APP_DISTRIBUTION} installs what it needs") from exc
    except ImportError as exc:                     # e.g. a Qt library without its system parts
        raise AppMissing(f"{what}: the app cannot start ({exc})") from exc


def app_installed() -> bool:
    """Whether the app distribution's package is there (not imported)."""
    from importlib.util import find_spec

    return find_spec("facetraj_app") is not None
