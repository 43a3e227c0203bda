"""Marker files in: one registry of formats (:mod:`.registry`), one module per format, each
reader returning a :class:`~.recording.MarkerRecording` (mm, facetraj's axes, named channels, the
rate, and what the file brings: audio, labels, a transcript, whether it is head-corrected).

A new format is one module here with a ``FORMATS`` tuple of :class:`~.registry.MarkerFormat`;
the registry, the error messages, corpus reading, ``corpus init`` and the app's Import find it.
"""

from .channels import NAMES_FILE, apply_names, check_names, read_names_file
from .recording import MarkerRecording
from .registry import (
    MarkerFormat,
    accepted,
    format_for,
    formats,
    held_recording,
    marker_suffixes,
    read_recording,
)

__all__ = ["NAMES_FILE", "MarkerFormat", "MarkerRecording", "accepted", "apply_names",
           "check_names", "format_for", "formats", "held_recording", "marker_suffixes", "read_names_file",
           "read_recording"]
