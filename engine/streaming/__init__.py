"""Streaming synthesis (live mode): audio blocks in, face frames out as soon as they are
determined; equal to the offline synthesis of the same audio (``tests/test_streaming.py``).

Imports ``engine.method`` and below.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "synthesizer": "LIVE_BATCH_FRAMES StreamConfig StreamFrames StreamingSynthesizer "
                   "stream_synthesize",
})
