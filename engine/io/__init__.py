"""Data in and out: every file facetraj reads or writes, checked at the boundary.

- ``files``: atomic writes (never a half-written file), output path checks, small JSON files;
- ``audio``, ``labelfiles`` (with ``textgrid``, Praat's TextGrid grammar), ``markerfiles`` (with
  ``c3d_check``, ``c3d_layout``): the file formats;
- ``corpus``: a corpus folder (``corpus.json`` and its recordings), ``hash_memo`` its content
  hashes, ``cachedir`` where recomputable things are kept;
- ``model_file``: a model file's arrays and metadata checked before use (no pickle); ``npz``
  writes models and trajectories (numpy's ``.npz``, without its copies);
- ``labelling``: which labels an input gets (a file, an aligned transcript, recognition), cached;
- ``export``: trajectories out as C3D, TSV/CSV or NPZ.

Imports the shared modules and ``facetraj_engine.labels``; never ``facetraj_engine.method`` or above.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "files": "atomic_write check_output_path read_json write_json",
    "audio": "AUDIO_SUFFIXES read_audio write_audio",
    "labelfiles": "LABEL_SUFFIXES read_labels read_textgrid read_textgrid_tiers write_textgrid "
                  "validate_phones write_label_map",
    "markerfiles": "MARKER_SUFFIXES MarkerData read_markers read_c3d write_c3d write_marker_tsv",
    "corpus": "Corpus CorpusInfo load_corpus init_corpus",
    "model_file": "read_model_file",
    "npz": "write_npz",
    "labelling": "labels_for_audio label_corpus relabelled label_folder",
    "export": "write_trajectories",
    "cachedir": "cache_dir",
})
