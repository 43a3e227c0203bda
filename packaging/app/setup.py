"""The app's version and its engine pin, read from the one place the version is written (the
engine's ``__init__.py``, linked here as ``engine_version.py``)."""

import re
from pathlib import Path

from setuptools import setup

VERSION = re.search(r'^__version__ = "([^"]+)"', (Path(__file__).parent / "engine_version.py").read_text(),
                    re.M)[1]

setup(version=VERSION, install_requires=[
    f"facetraj-engine=={VERSION}",
    "PyQt6==6.11.*",
    "pyvista>=0.43",
    "pyvistaqt>=0.11",
    "matplotlib>=3.8",
    "imageio>=2.30",
    "imageio-ffmpeg>=0.4.9",
])
