"""The model reader (facetraj_engine.io.model_file): every array's data type, shape, values and
cross-references are checked before anything uses the model; each check is tested here with a
model file damaged in that one way."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import edited_model_file

from facetraj_engine.errors import ModelFileError
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import synthesize


@pytest.fixture(scope="module")
def saved(toy_model, tmp_path_factory):
    path = tmp_path_factory.mktemp("model") / "m.npz"
    return toy_model.save(path)


def _arrays(path):
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _huge_id(a, meta=None):
    b = a.astype(np.uint64)
    b[0, 0] = 2**64 - 1
    return b


def _dup_first(a, meta=None):
    b = a.copy()
    b[1] = b[0]
    return b


def _unsorted_offsets(a, meta=None):
    b = a.copy()
    b[1], b[2] = b[2], b[1] - 1
    return b


def _asymmetric(a, meta=None):
    b = a.copy()
    b[0, 1] += 1.0
    return b


def _diagonal(a, meta=None):
    return a + np.eye(len(a))


def _reversed_lsf(a, meta=None):
    return a[:, ::-1].copy()


def _late_start(a, meta=None):
    b = a.copy()
    b[0] = 1e6
    return b


def _one(a, value):
    b = a.copy()
    b.flat[b.size // 2] = value
    return b


# name, how the array is changed, what the error says
DAMAGE = [
    ("cb_contexts", lambda a, m: a.astype(np.float64), "array 'cb_contexts' has data type float64, "
                                                       "not whole numbers"),
    ("fixed", lambda a, m: a.astype(np.bool_), "array 'fixed' has data type bool"),
    ("cb_lsf", lambda a, m: a.astype(np.int64), "array 'cb_lsf' has data type int64, not "
                                                "floating-point numbers"),
    ("pca_components", lambda a, m: a.astype(np.complex64), "has data type complex64"),
    ("means", lambda a, m: np.array(["x"] * a.shape[0]), "array 'means' has data type <U1"),
    ("cb_lsf", lambda a, m: a[:, :-1], "array 'cb_lsf' has shape"),
    ("cb_pcs", lambda a, m: a.T.copy(), "array 'cb_pcs' has shape"),
    ("means", lambda a, m: np.full_like(a, np.nan), "array 'means' holds NaN or infinite values"),
    ("reference", lambda a, m: a.astype(np.longdouble) * np.longdouble(1e308) * 10,
     "array 'reference' holds NaN or infinite values"),
    ("cb_pcs", lambda a, m: _one(a, np.inf), "array 'cb_pcs' holds NaN or infinite values"),
    ("cb_lsf_context", lambda a, m: _one(a, np.nan), "array 'cb_lsf_context' holds NaN or "
                                                     "infinite values"),
    ("cb_contexts", lambda a, m: a + len(m["phones"]), "array 'cb_contexts' holds indices outside "
                                                       "0.."),
    ("cb_contexts", lambda a, m: a - 100, "array 'cb_contexts' holds indices outside 0.."),
    ("cb_contexts", lambda a, m: _huge_id(a), "array 'cb_contexts' holds indices outside 0..2^63"),
    ("fixed", lambda a, m: a + 1000, "array 'fixed' holds indices outside 0.."),
    ("fixed", _dup_first, "array 'fixed' names a marker twice"),
    ("cb_token_utt", lambda a, m: a + len(m["train_utterances"]), "array 'cb_token_utt' holds "
                                                                  "indices outside"),
    ("ix_order", _dup_first, "its LSF index does not match its codebook"),
    ("ix_order", lambda a, m: a + 1, "its LSF index does not match its codebook"),
    ("ix_order", lambda a, m: a.astype(np.float32), "its LSF index does not match its codebook"),
    ("ix_offsets", _unsorted_offsets, "its LSF index does not match its codebook"),
    ("ix_offsets", lambda a, m: a * 2, "its LSF index does not match its codebook"),
    ("ix_centroids", None, "its LSF index does not match its codebook"),
    ("ix_centroids", lambda a, m: a + 4.0, "array 'ix_centroids' holds LSFs outside 0..pi"),
    ("cb_lsf", lambda a, m: a + 4.0, "array 'cb_lsf' holds LSFs outside 0..pi or out of order"),
    ("cb_lsf", _reversed_lsf, "array 'cb_lsf' holds LSFs outside 0..pi or out of order"),
    ("cb_lsf_context", lambda a, m: -a, "array 'cb_lsf_context' holds LSFs outside 0..pi"),
    ("cb_token_start", _late_start, "hold a phone token that starts before 0 s or ends before it "
                                    "starts"),
    ("cb_token_start", lambda a, m: a - 1e3, "hold a phone token that starts before 0 s"),
    ("pca_components", lambda a, m: 2 * a, "array 'pca_components' does not hold orthonormal "
                                           "components"),
    ("pca_variances", lambda a, m: -a, "negative variances or deviations in the model"),
    ("pca_variances", lambda a, m: a * 1000, "the PCs' variances add up to more than the total "
                                             "variance"),
    ("coord_std", lambda a, m: -a - 1, "negative variances or deviations in the model"),
    ("distances", lambda a, m: -a, "array 'distances' is not a matrix of distances"),
    ("distances", _asymmetric, "array 'distances' is not a matrix of distances"),
    ("distances", _diagonal, "array 'distances' is not a matrix of distances"),
]


@pytest.mark.parametrize("name, damage, phrase", DAMAGE,
                         ids=[f"{n}-{p[:30]}" for n, _, p in DAMAGE])
def test_each_damage_is_refused_with_its_message(saved, tmp_path, name, damage, phrase):
    a = _arrays(saved)
    meta = json.loads(str(a["meta"]))
    bad = edited_model_file(saved, tmp_path / "bad.npz",
                            **{name: None if damage is None else damage(a[name], meta)})
    with pytest.raises(ModelFileError) as exc:
        Model.load(bad)
    assert phrase in str(exc.value)
    assert str(exc.value).startswith(str(bad) + ": ")


def test_finite_values_whose_sum_overflows_are_read(saved, tmp_path):
    """The finite check sums each array first (NaN and inf reach the sum); a sum that overflows
    on finite values is not taken for a damaged array."""
    a = _arrays(saved)
    pcs = a["cb_pcs"].copy()
    pcs[:2, 0] = 1.7e308
    ok = edited_model_file(saved, tmp_path / "huge.npz", cb_pcs=pcs)
    assert Model.load(ok).codebook.pcs[1, 0] == 1.7e308


@pytest.mark.parametrize("edit, phrase", [
    (lambda m: {**m, "phones": [p for p in m["phones"] if p != "sil"]},
     "metadata 'phones' is"),
    (lambda m: {**m, "tuned": {"settings": {"n_context_phones": 1e30}}},
     "metadata 'tuned' setting 'n_context_phones' is 1e+30, not a whole number from 1 to 1000"),
    (lambda m: {**m, "tuned": {"settings": {"triangle_s": 0.0}}},
     "setting 'triangle_s' is 0.0, not a number from 0.001 to 10"),
    (lambda m: {**m, "tuned": {"settings": {"n_context_phones": 2.5}}},
     "setting 'n_context_phones' is 2.5, not a whole number"),
    (lambda m: {**m, "tuned": ["x"]}, "metadata 'tuned' is ['x'], not an object"),
])
def test_metadata_damage_is_refused(saved, tmp_path, edit, phrase):
    meta = json.loads(str(_arrays(saved)["meta"]))
    bad = edited_model_file(saved, tmp_path / "bad.npz", meta=np.array(json.dumps(edit(meta))))
    with pytest.raises(ModelFileError, match="^" + str(bad).replace(".", r"\.")) as exc:
        Model.load(bad)
    assert phrase in str(exc.value), str(exc.value)


def test_other_number_types_are_read_as_the_method_computes(saved, tmp_path, toy_corpus):
    """Context ids as uint64 (issue 26: a numpy casting error in synthesis), big-endian floats,
    32-bit ids: read as int64 and float64, and the synthesis is the same."""
    a = _arrays(saved)
    other = edited_model_file(saved, tmp_path / "other.npz",
                              cb_contexts=a["cb_contexts"].astype(np.uint64),
                              ix_order=a["ix_order"].astype(np.int32),
                              cb_lsf=a["cb_lsf"].astype(">f8"), means=a["means"].astype(">f8"))
    m0, m1 = Model.load(saved), Model.load(other)
    assert m1.codebook.contexts.dtype == np.int64 and m1.codebook.lsf.dtype == np.float64
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    for mode in ("phonetic", "acoustic"):
        from facetraj_engine.config import SynthConfig

        cfg = SynthConfig(mode=mode)
        r0 = synthesize(m0, utt.audio, utt.sample_rate, utt.phones, cfg, n_frames=utt.n_frames)
        r1 = synthesize(m1, utt.audio, utt.sample_rate, utt.phones, cfg, n_frames=utt.n_frames)
        np.testing.assert_array_equal(r0.markers, r1.markers)


def test_uint64_context_ids_synthesize_from_the_command_line(saved, tmp_path, toy_corpus_dir,
                                                              capsys):
    from facetraj.cli import main

    a = _arrays(saved)
    other = edited_model_file(saved, tmp_path / "u64.npz",
                              cb_contexts=a["cb_contexts"].astype(np.uint64))
    code = main(["synth", str(other), str(toy_corpus_dir / "toy030.wav"), "--labels",
                 str(toy_corpus_dir / "toy030.TextGrid"), "-o", str(tmp_path / "o.tsv"), "-q"])
    assert code == 0, capsys.readouterr().err
