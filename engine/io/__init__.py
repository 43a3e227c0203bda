"""Data in and out: every file facetraj reads or writes, checked at the boundary.

- ``files``: atomic writes (never a half-written file), output path checks, small JSON files;
- ``audio``, ``labelfiles`` (with ``textgrid``, Praat's TextGrid grammar), ``markerfiles`` (with
  ``c3d_check``, ``c3d_layout``): the file formats; ``markerformats``: the one registry of marker
  file formats, a module per format (C3D, tables, MOCHA, EST, Carstens, NDI Wave, MVIEW, XRMB);
- ``corpus``: a corpus folder (``corpus.json`` and its recordings), ``hash_memo`` its content
  hashes, ``cachedir`` where recomputable things are kept;
- ``sensor_roles``: which articulograph sensor is which articulator (tongue, lips, jaw, palate,
  velum, reference), from the names and ``corpus.json``'s ``sensor_roles``;
- ``model_file``: a model file's arrays and metadata checked before use (no pickle);
- ``label_rule``: which labels a recording gets (the one rule: a file, an aligned transcript,
  recognition), automatic labels cached; ``labelling``: automatic labels of corpora and folders;
- ``export``: trajectories out as C3D, TSV/CSV or NPZ.

Imports the shared modules and ``facetraj_engine.labels``; never ``facetraj_engine.method`` or above.
"""

from .. import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "files": "atomic_write check_output_path read_json write_json write_npz",
    "audio": "AUDIO_SUFFIXES read_audio write_audio",
    "labelfiles": "LABEL_SUFFIXES read_labels read_textgrid read_textgrid_tiers write_textgrid "
                  "validate_phones write_label_map",
    "markerfiles": "MARKER_SUFFIXES MarkerData read_markers read_c3d write_c3d write_marker_tsv",
    "corpus": "Corpus CorpusInfo load_corpus init_corpus",
    "sensor_roles": "SensorRoles sensor_roles",
    "model_file": "read_model_file",
    "label_rule": "resolve_labels LabelRequest FoundLabels label_audio",
    "labelling": "label_corpus relabelled label_folder",
    "export": "write_trajectories",
    "cachedir": "cache_dir",
})
