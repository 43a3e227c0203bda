"""Training, synthesis and the model file on the toy corpus (fast, end to end)."""

import json
import zipfile

import numpy as np
import pytest
from conftest import edited_model_file

from facetraj_engine.config import SynthConfig, TrainConfig
from facetraj_engine.data import PhoneSegment, Utterance
from facetraj_engine.errors import InputError, ModelFileError
from facetraj_engine.evaluation.scores import evaluate
from facetraj_engine.method.model import Model
from facetraj_engine.method.pipeline import resmooth, synthesize
from facetraj_engine.method.training import MarkerSetup, train


def test_model_contents(toy_model, toy_corpus):
    m = toy_model
    assert m.pca.n_components == 20 and m.pca.explained_ratio.sum() > 0.99
    assert set(m.phones) == {"sil", "aa", "iy", "uw", "m", "f", "s", "t"}
    cb = m.codebook
    assert cb.lsf.shape == (cb.n_contexts * 5, 18) and cb.pcs.shape == (cb.n_contexts * 5, 20)
    assert cb.contexts.shape[1] == 7
    assert np.all(np.isfinite(cb.lsf)) and np.all(np.isfinite(cb.pcs))
    s = m.similarity()
    assert np.allclose(np.diag(s), 1.0) and np.allclose(s, s.T)
    # PC1 of the toy face is the jaw: chin and lower lip y dominate its loadings
    pc1 = np.abs(m.pca.components[0].reshape(-1, 3))
    names = m.marker_names
    top2 = {divmod(int(i), 3) for i in np.argsort(pc1.ravel())[-2:]}
    assert top2 == {(names.index("CHIN"), 1), (names.index("LL_C"), 1)}


def test_save_load_round_trip_bit_for_bit(toy_model, tmp_path):
    path = toy_model.save(tmp_path / "m.npz")
    back = Model.load(path)
    for name in ("fixed", "reference", "means", "distances", "coord_std"):
        assert np.array_equal(getattr(back, name), getattr(toy_model, name))
    for name in ("mean", "components", "variances"):
        assert np.array_equal(getattr(back.pca, name), getattr(toy_model.pca, name))
    for name in ("contexts", "lsf", "pcs", "token_utt", "token_start", "token_end"):
        assert np.array_equal(getattr(back.codebook, name), getattr(toy_model.codebook, name))
    for name in ("centroids", "order", "offsets"):
        assert np.array_equal(getattr(back.index, name), getattr(toy_model.index, name))
    assert back.config == toy_model.config and back.phones == toy_model.phones
    assert back.marker_names == toy_model.marker_names and back.scale == toy_model.scale
    with zipfile.ZipFile(path) as z:
        assert all(not n.endswith(".pkl") for n in z.namelist())
    # loading needs no pickle
    with np.load(path, allow_pickle=False) as z:
        assert json.loads(str(z["meta"]))["format"] == "facetraj-model"


def test_a_model_is_stored_uncompressed_and_a_compressed_one_still_loads(toy_model, tmp_path):
    from facetraj_engine.io.model_file import is_compressed

    path = toy_model.save(tmp_path / "m.npz")
    with zipfile.ZipFile(path) as z:
        assert {i.compress_type for i in z.infolist()} == {zipfile.ZIP_STORED}
    assert not is_compressed(path)
    old = tmp_path / "old.npz"                    # as facetraj wrote models before
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(old, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            dst.writestr(info.filename, src.read(info))
    assert is_compressed(old) and not is_compressed(tmp_path / "absent.npz")
    back = Model.load(old)
    assert np.array_equal(back.codebook.lsf, toy_model.codebook.lsf) and back.phones == toy_model.phones


def test_a_compressed_cached_model_is_stored_uncompressed_once(toy_model, toy_corpus, tmp_path,
                                                                monkeypatch):
    from facetraj_app.cache import cached_model_path, load_or_train
    from facetraj_engine.io.model_file import is_compressed

    monkeypatch.setenv("FACETRAJ_CACHE_DIR", str(tmp_path / "cache"))
    path = cached_model_path(toy_corpus)
    path.parent.mkdir(parents=True)
    saved = toy_model.save(tmp_path / "m.npz")
    with zipfile.ZipFile(saved) as src, zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            dst.writestr(info.filename, src.read(info))
    first = load_or_train(toy_corpus)
    assert not is_compressed(path)
    assert path.read_bytes() == saved.read_bytes()           # as Model.save writes it now
    again = load_or_train(toy_corpus)
    for model in (first, again):
        assert np.array_equal(model.codebook.pcs, toy_model.codebook.pcs)


def test_bad_model_files(toy_model, tmp_path):
    (tmp_path / "text.npz").write_text("hello")
    with pytest.raises(ModelFileError, match="text.npz: not a facetraj model"):
        Model.load(tmp_path / "text.npz")
    good = toy_model.save(tmp_path / "good.npz").read_bytes()
    (tmp_path / "trunc.npz").write_bytes(good[: len(good) // 2])
    with pytest.raises(ModelFileError, match="trunc.npz"):
        Model.load(tmp_path / "trunc.npz")
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    with pytest.raises(ModelFileError, match="no metadata"):
        Model.load(tmp_path / "other.npz")
    meta = {"format": "facetraj-model", "version": 99}
    np.savez(tmp_path / "newer.npz", meta=np.array(json.dumps(meta)))
    with pytest.raises(ModelFileError, match="newer"):
        Model.load(tmp_path / "newer.npz")
    with pytest.raises(ModelFileError, match="no such model"):
        Model.load(tmp_path / "absent.npz")
    # a damaged LSF index (codeword ids out of range) is refused, not used
    bad = edited_model_file(tmp_path / "good.npz", tmp_path / "badindex.npz",
                            ix_order=toy_model.index.order + 1)
    with pytest.raises(ModelFileError, match="badindex.npz: its LSF index does not match"):
        Model.load(bad)


def test_synthesis_outputs(toy_model, toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    res = synthesize(toy_model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(),
                     n_frames=utt.n_frames)
    t = utt.n_frames
    assert res.markers.shape == (t, 12, 3) and res.pcs.shape == (t, 20)
    assert res.frames.candidates.shape == (t, 15)                  # 5N codewords, N = 3
    np.testing.assert_allclose(res.frames.weights.sum(axis=1), 1.0)
    assert np.all((res.frames.gamma >= 0.2) & (res.frames.gamma <= 2.0))
    assert len(res.segments) == len(utt.phones)
    seg = res.segments[2]
    assert toy_model.codebook.centre[seg.chosen[0]] == seg.context[3]   # centre phone matches
    spline = resmooth(toy_model, res, "spline")
    assert spline.shape == res.markers.shape and not np.allclose(spline, res.markers)
    full = synthesize(toy_model, utt.audio, utt.sample_rate, None,
                      SynthConfig(mode="acoustic", acoustic_prefilter=None), n_frames=t)
    assert full.frames.candidates.shape[1] == len(toy_model.codebook.lsf)   # all 5L
    exact = synthesize(toy_model, utt.audio, utt.sample_rate, None,
                       SynthConfig(mode="acoustic", acoustic_prefilter=50, acoustic_probe=None),
                       n_frames=t)
    assert exact.frames.candidates.shape[1] == 50
    indexed = synthesize(toy_model, utt.audio, utt.sample_rate, None,
                         SynthConfig(mode="acoustic", acoustic_prefilter=50), n_frames=t)
    assert indexed.frames.candidates.shape[1] == 50
    # the index finds most of the exact 50 nearest, and the faces agree closely
    found = [len(np.intersect1d(a, b)) / 50 for a, b in
             zip(indexed.frames.candidates, exact.frames.candidates, strict=True)]
    assert np.mean(found) > 0.9
    assert np.abs(indexed.markers - exact.markers).max() < 0.05 * np.ptp(exact.markers)
    # input LSFs computed once and passed in give the same synthesis
    w = toy_model.input_lsf(utt.audio, utt.sample_rate, res.times)
    again = synthesize(toy_model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(),
                       n_frames=t, lsf=w)
    assert np.array_equal(again.markers, res.markers) and np.array_equal(again.lsf, res.lsf)
    with pytest.raises(ValueError, match="lsf must be"):
        synthesize(toy_model, utt.audio, utt.sample_rate, utt.phones, SynthConfig(), n_frames=t,
                   lsf=w[1:])


def test_synthesis_bad_input(toy_model, toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.test[0])
    with pytest.raises(InputError, match="needs phone labels"):
        synthesize(toy_model, utt.audio, utt.sample_rate, None, SynthConfig(), source="a.wav")
    with pytest.raises(InputError, match="too short"):
        synthesize(toy_model, utt.audio[:100], utt.sample_rate, None,
                   SynthConfig(mode="acoustic"), source="a.wav")
    unknown = [PhoneSegment(s.start, s.end, "zz" if i == 2 else s.label)
               for i, s in enumerate(utt.phones)]
    with pytest.raises(InputError, match="x.TextGrid: phone 'zz'.*known phones"):
        synthesize(toy_model, utt.audio, utt.sample_rate, unknown, source="x.TextGrid")
    short = utt.phones[:-1]
    with pytest.raises(InputError, match="labels end at"):
        synthesize(toy_model, utt.audio, utt.sample_rate, short, source="x.TextGrid")
    with pytest.raises(ValueError, match="markers must be"):
        toy_model.normalise_markers(np.zeros((5, 3, 3)))


def test_training_errors(toy_corpus):
    utt = toy_corpus.utterance(toy_corpus.info.train[0])
    setup = MarkerSetup(["FH_L", "FH_R", "NB", "NT"], "UL_C", "LL_C")
    other = Utterance("odd", utt.audio, utt.sample_rate, utt.phones, utt.markers[:, :10],
                      60.0, utt.marker_names[:10])
    with pytest.raises(InputError, match="odd: marker set differs"):
        train([utt, other], setup)
    one = Utterance("one", utt.audio, utt.sample_rate, utt.phones, utt.markers[:1], 60.0,
                    utt.marker_names)
    with pytest.raises(InputError, match="one: only one marker frame"):
        train([one], setup)
    with pytest.raises(InputError, match="'NOSE'"):
        train([utt], MarkerSetup(["NOSE", "FH_R", "NB"], "UL_C", "LL_C"))


def test_training_options(toy_corpus):
    m = train(toy_corpus, config=TrainConfig(n_components=None, variance_target=0.95, context=1,
                                              codewords_per_phone=3, placement="edges"))
    assert m.pca.explained_ratio.sum() >= 0.95 and m.pca.n_components < 20
    assert m.codebook.contexts.shape[1] == 3 and m.codebook.n_per_phone == 3


def test_toy_end_to_end(toy_model, toy_corpus):
    res = evaluate(toy_model, toy_corpus, ("test",), [SynthConfig()], ("triangular", "spline"))
    tri = res.mean("test", "triangular")
    assert tri["lower_lip"] > 0.9 and tri["upper_lip"] > 0.9 and tri["whole_face"] > 0.9
    assert len(res.scores) == 2 * len(toy_corpus.info.test)
