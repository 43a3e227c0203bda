"""Streaming (live mode): audio blocks in, face frames out as soon as they are determined.

Acoustic-only, equal to the offline synthesis of the same audio (``synthesizer``,
``tests/test_streaming.py``); with phones recognized as they are spoken (``live``: the
``recognizer`` beside the ``phonetic`` synthesizer, the ``closure`` step streamed; issue 27).

Imports ``facetraj_engine.method`` and below.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "synthesizer": "LIVE_BATCH_FRAMES StreamConfig StreamFrames StreamingSynthesizer "
                   "stream_synthesize",
    "live": "LIVE_RECOGNIZER LIVE_TIMING LiveConfig LiveStream live_mode stream_file",
    "recognizer": "RecognizerConfig RunningCmn StreamingRecognizer",
    "phonetic": "PhoneticSynthesizer PhoneticTiming",
})
