"""Bringing one's own data: the real MOCHA-TIMIT sample in ../shared (read in place, never copied),
EST tracks, corpus descriptions for read-only folders, bad lab data."""

import logging

import numpy as np
import pytest
from conftest import MOCHA

from facetraj_engine.config import SynthConfig
from facetraj_engine.errors import FILE_WARNINGS, InputError
from facetraj_engine.io.corpus import init_corpus, load_corpus
from facetraj_engine.io.markerfiles import MOCHA_COILS, read_markers, read_mocha_ema, write_c3d
from facetraj_engine.labels.labelmap import MOCHA_TO_ARPABET, read_label_map
from facetraj_engine.method.pipeline import synthesize
from facetraj_engine.method.training import train

needs_mocha = pytest.mark.skipif(not (MOCHA / "fsew0_001.ema").exists(),
                                 reason="the MOCHA sample ../shared/data/mocha_fsew0_001 is absent")


@needs_mocha
def test_mocha_ema_ascii():
    d = read_mocha_ema(MOCHA / "fsew0_001.ema")
    assert d.rate == 500.0 and d.markers.shape == (966, 9, 3) and d.names == list(MOCHA_COILS)
    assert not d.markers[..., 0].any()                       # midsagittal: x = 0
    y = {n: d.markers[:, i, 1] for i, n in enumerate(d.names)}
    z = {n: d.markers[:, i, 2] for i, n in enumerate(d.names)}
    assert y["BN"].mean() > y["UL"].mean() > y["LL"].mean()   # nose above upper above lower lip
    assert z["UL"].mean() > z["TD"].mean() > z["V"].mean()    # lips in front of tongue, velum
    raw = np.loadtxt(MOCHA / "fsew0_001.ema")
    np.testing.assert_allclose(d.markers[:, d.names.index("LL"), 1], raw[:, 10] / 100)


@needs_mocha
@pytest.mark.parametrize("kind", ["ascii", "binary"])
def test_mocha_est_track_matches_ascii(tmp_path, kind):
    raw = np.loadtxt(MOCHA / "fsew0_001.ema")
    names = [f"c{i}" for i in range(20)]
    for coil, (cx, cy) in MOCHA_COILS.items():
        names[cx - 3], names[cy - 3] = f"{coil.lower()}_x", f"{coil.lower()}_y"
    order = list(range(20))[::-1]        # channels stored in another order: found by name
    header = ["EST_File Track", f"DataType {kind}", "ByteOrder 10", f"NumFrames {len(raw)}",
              "NumChannels 20", "EqualSpace 1", "BreaksPresent true"]
    header += [f"Channel_{j} {names[c]}" for j, c in enumerate(order)]
    header += ["EST_Header_End"]
    rows = np.column_stack([raw[:, 0], np.ones(len(raw)), raw[:, 2:][:, order]])
    body = (rows.astype(">f4").tobytes() if kind == "binary"
            else "\n".join(" ".join(f"{v:.6f}" for v in r) for r in rows).encode() + b"\n")
    path = tmp_path / "x.ema"
    path.write_bytes("\n".join(header).encode() + b"\n" + body)
    est = read_mocha_ema(path)
    ascii_ = read_mocha_ema(MOCHA / "fsew0_001.ema")
    np.testing.assert_allclose(est.markers, ascii_.markers, atol=1e-3)


@pytest.fixture(scope="module")
def mocha_corpus(tmp_path_factory):
    if not (MOCHA / "fsew0_001.ema").exists():
        pytest.skip("the MOCHA sample ../shared/data/mocha_fsew0_001 is absent")
    out, _ = init_corpus(MOCHA, tmp_path_factory.mktemp("mocha") / "mocha.json", ["UI", "BN"],
                         "UL", "LL", label_map="mocha", test_fraction=0)
    return load_corpus(out)


def test_mocha_as_a_corpus(mocha_corpus, caplog):
    assert mocha_corpus.info.dimensions == 2 and mocha_corpus.info.data_dir
    assert not list(MOCHA.glob("corpus.json"))                 # nothing written into shared/
    FILE_WARNINGS.clear()            # logged once per file and process: another test may have read it
    with caplog.at_level(logging.WARNING):
        utt = mocha_corpus.utterance("fsew0_001")
    assert "markers end at 1.92 s but the audio at 2.22 s" in caplog.text
    assert [p.label for p in utt.phones][:6] == ["sil", "sil", "sil", "dh", "ih", "s"]
    n = int(np.floor(utt.duration * 60)) + 1
    assert utt.markers.shape == (n, 9, 3)
    assert np.isnan(utt.markers[-10:]).all() and np.isfinite(utt.markers[:100]).all()
    # lips and jaw move with the speech: the lower lip travels further than the upper incisor
    ll = utt.markers[:100, utt.marker_names.index("LL"), 1]
    ui = utt.markers[:100, utt.marker_names.index("UI"), 1]
    assert np.ptp(ll) > 5 * np.ptp(ui)


def test_train_on_midsagittal_data(mocha_corpus):
    model = train(mocha_corpus)
    assert model.pca.explained_ratio[0] > 0.3
    assert not model.neutral_face()[:, 0].any()
    assert "dh" in model.phones and "breath" not in model.phones


def test_default_model_synthesizes_mocha_audio(default_model, mocha_corpus):
    utt = mocha_corpus.utterance("fsew0_001")
    for mode in ("phonetic", "acoustic"):
        res = synthesize(default_model, utt.audio, utt.sample_rate, utt.phones,
                         SynthConfig(mode=mode), source="fsew0_001")
        assert res.markers.shape == (len(res.times), default_model.n_markers, 3)
        assert np.isfinite(res.markers).all()
        lips = res.markers[:, default_model.lower_lip, 1] - res.markers[:, default_model.upper_lip, 1]
        assert np.ptp(lips) > 1.0                               # the mouth opens and closes


def test_label_map_file(tmp_path):
    (tmp_path / "map.tsv").write_text("# mine\n@\tah\nii\tiy\n")
    assert read_label_map(tmp_path / "map.tsv") == {"@": "ah", "ii": "iy"}
    assert read_label_map("mocha") == MOCHA_TO_ARPABET
    (tmp_path / "bad.tsv").write_text("@ ah extra\n")
    with pytest.raises(InputError, match="line 1"):
        read_label_map(tmp_path / "bad.tsv")


def test_marker_set_mismatch_and_resampling(tmp_path, toy_corpus_dir):
    corpus = load_corpus(toy_corpus_dir)
    utt = corpus.utterance(corpus.info.train[0])
    for ext in ("wav", "TextGrid"):
        (tmp_path / f"u.{ext}").write_bytes((toy_corpus_dir / f"{utt.name}.{ext}").read_bytes())
    write_c3d(tmp_path / "u.c3d", utt.markers[:, :11], 60.0, utt.marker_names[:11])
    info = corpus.info
    from facetraj_engine.io.corpus import CorpusInfo, save_corpus_info

    save_corpus_info(tmp_path, CorpusInfo(**{**info.__dict__, "train": ["u"], "test": []}))
    with pytest.raises(InputError, match="u.c3d: marker set differs"):
        load_corpus(tmp_path).utterance("u")
    # a 120 Hz recording is brought to the corpus rate
    t120 = np.arange(0, utt.n_frames, 0.5)
    m120 = np.stack([np.interp(t120, np.arange(utt.n_frames), c)
                     for c in utt.markers.reshape(utt.n_frames, -1).T], axis=1)
    write_c3d(tmp_path / "v.c3d", m120.reshape(len(t120), 12, 3), 120.0, utt.marker_names)
    back = read_markers(tmp_path / "v.c3d", 60.0)
    assert back.rate == 60.0 and abs(back.markers.shape[0] - utt.n_frames) <= 1
