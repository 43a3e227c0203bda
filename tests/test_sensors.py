"""Articulograph sensors as articulators (issue 47), without a display: which sensor is which
(``facetraj_engine.io.sensor_roles``, overridable in corpus.json), and per-sensor scoring
(``facetraj_engine.evaluation.sensors``): r and RMSE in mm of every sensor coordinate, through
``facetraj eval`` on the MOCHA-TIMIT sample and on an MVIEW file made from it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from articulograph import HPRC_NAMES, mview_from_mocha
from conftest import MOCHA

from facetraj.cli import main
from facetraj_engine.analysis.articulators import jaw_top, measure, tongue_curve
from facetraj_engine.errors import InputError, ModelFileError
from facetraj_engine.evaluation.sensors import STILL_MM, pooled, sensor_scores
from facetraj_engine.io.corpus import init_corpus, load_corpus
from facetraj_engine.io.sensor_roles import sensor_roles
from facetraj_engine.method.model import Model

needs_mocha = pytest.mark.skipif(not (MOCHA / "fsew0_001.ema").exists(),
                                 reason="the MOCHA sample ../shared/data/mocha_fsew0_001 is absent")


def named(roles, role: str) -> list[str]:
    return [roles.names[i] for i in getattr(roles, role)]


# ---------------------------------------------------------------------- roles from names
@pytest.mark.parametrize("names, upper, lower, tongue, jaw, reference", [
    # HPRC (MVIEW): tongue rear, body, tip; the mouth's left corner; two jaw sensors
    (HPRC_NAMES, "UL", "LL", ["TT", "TB", "TR"], ["JAW", "JAWL"], []),
    # MOCHA-TIMIT: lower and upper incisor, velum, nose bridge
    (["UI", "LI", "UL", "LL", "TT", "TB", "TD", "V", "BN"], "UL", "LL", ["TT", "TB", "TD"], ["LI"],
     ["UI", "BN"]),
    # mngu0 (EST channels T1_py ...): numbered tongue sensors, tip first, named lips and jaw
    (["T3", "T2", "T1", "jaw", "upperlip", "lowerlip", "ref"], "upperlip", "lowerlip",
     ["T1", "T2", "T3"], ["jaw"], ["ref"]),
    # Carstens / VisArtico: TTIP TMID TBACK, reference sensors behind the ears and on the nose
    (["TBACK", "TMID", "TTIP", "ULIP", "LLIP", "JAW", "LEAR", "REAR", "NOSE"], "ULIP", "LLIP",
     ["TTIP", "TMID", "TBACK"], ["JAW"], ["LEAR", "REAR", "NOSE"]),
    # XRMB pellets: T1 (tip) to T4, the mandible's incisor and molar pellets
    (["UL", "LL", "T1", "T2", "T3", "T4", "MNI", "MNM"], "UL", "LL", ["T1", "T2", "T3", "T4"],
     ["MNI", "MNM"], []),
])
def test_roles_from_the_naming_conventions(names, upper, lower, tongue, jaw, reference):
    r = sensor_roles(names, names.index(upper), names.index(lower))
    assert r.articulograph
    assert named(r, "tongue") == tongue and named(r, "jaw") == jaw
    assert named(r, "reference") == reference
    assert r.role(names.index(upper)) == "upper lip" and r.role(names.index(lower)) == "lower lip"


def test_a_face_is_not_an_articulograph(default_corpus):
    info = default_corpus.info
    names = info.marker_names
    r = sensor_roles(names, names.index(info.upper_lip), names.index(info.lower_lip),
                     fixed=[names.index(n) for n in info.fixed_markers])
    assert not r.articulograph and not r.tongue
    assert named(r, "reference") == info.fixed_markers          # the corpus's fixed markers


def test_overrides_replace_the_names():
    names = ["A1", "A2", "A3", "UL", "LL", "TT", "X"]
    r = sensor_roles(names, 3, 4, overrides={"tongue": ["A3", "A2", "A1"], "jaw": ["X"],
                                             "other": ["TT"]})
    assert named(r, "tongue") == ["A3", "A2", "A1"] and named(r, "jaw") == ["X"]
    assert r.role(names.index("TT")) == "other"              # no longer the tongue's
    assert not sensor_roles(names, 3, 4, overrides={"tongue": []}).articulograph


@needs_mocha
@pytest.mark.parametrize("roles, message", [
    ({"tongue": ["TT", "XX"]}, "'sensor_roles' names 'XX', not among marker_names"),
    ({"teeth": ["TT"]}, "'sensor_roles' has the role 'teeth', not one of tongue jaw"),
    ({"tongue": ["TT"], "jaw": ["TT"]}, "'sensor_roles' gives 'TT' two roles"),
    ({"tongue": "TT"}, "'sensor_roles' 'tongue' is not a list of marker names"),
    ([], "'sensor_roles' is [], not an object of role lists"),
])
def test_bad_sensor_roles_in_corpus_json(roles, message, tmp_path):
    path, _ = init_corpus(MOCHA, tmp_path / "c.json", ["UI", "BN"], "UL", "LL", label_map="mocha",
                          test_fraction=0)
    obj = json.loads(path.read_text())
    obj["sensor_roles"] = roles
    path.write_text(json.dumps(obj))
    with pytest.raises(InputError) as err:
        load_corpus(path)
    assert str(err.value).startswith(str(path)) and message in str(err.value)
    assert "\n" not in str(err.value)


# ---------------------------------------------------------------------- the tongue curve
def test_tongue_curve_passes_through_every_sensor_in_order():
    rng = np.random.default_rng(47)
    pts = np.cumsum(rng.uniform(5, 15, (4, 3)), axis=0)
    curve = tongue_curve(pts, 10)
    assert len(curve) == 31
    np.testing.assert_array_equal(curve[::10], pts)          # exactly through each, in order
    steps = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    assert steps.max() < 0.5 * np.linalg.norm(np.diff(pts, axis=0), axis=1).min()   # smooth
    np.testing.assert_array_equal(tongue_curve(pts[:1]), pts[:1])


# ---------------------------------------------------------------------- per-sensor scores
class _Model:
    """What sensor_scores reads of a model."""

    def __init__(self, names, std):
        self.n_markers = len(names)
        self.coord_std = np.asarray(std, float).ravel()
        self.roles = sensor_roles(names, 1, 2, fixed=[3])


def test_sensor_scores_against_numpy():
    rng = np.random.default_rng(3)
    t = 200
    orig = rng.normal(0, 3, (t, 4, 3))
    syn = orig + rng.normal(0, 1, (t, 4, 3))
    syn[50:60, 0, 1] = np.nan                                  # a gap in one coordinate only
    mask = np.ones(t, bool)
    mask[:20] = False
    std = np.ones((4, 3))
    std[:, 0] = 0.0                                            # x never moves: left out
    std[3, 2] = STILL_MM / 2
    model = _Model(["TT", "UL", "LL", "REF"], std)
    scores = {c.key: c for c in sensor_scores(orig, syn, mask, model)}
    assert list(scores) == ["TT y", "TT z", "UL y", "UL z", "LL y", "LL z", "REF y"]
    for key, c in scores.items():
        m, a = ["TT", "UL", "LL", "REF"].index(c.sensor), "xyz".index(c.axis)
        ok = mask & np.isfinite(syn[:, m, a])
        assert c.frames == ok.sum() == (170 if key == "TT y" else 180)
        assert c.r == pytest.approx(np.corrcoef(orig[ok, m, a], syn[ok, m, a])[0, 1], abs=1e-12)
        assert c.rmse_mm == pytest.approx(np.sqrt(np.mean((orig[ok, m, a] - syn[ok, m, a]) ** 2)))
    assert scores["TT y"].role == "tongue" and scores["REF y"].role == "reference"
    # over two utterances: r averaged, the RMSE pooled over their frames, references not in
    # the articulators' mean
    other = sensor_scores(orig[::-1], syn, mask, model)
    table = pooled([list(scores.values()), other])
    tt = table.row("TT y")
    o = {c.key: c for c in other}["TT y"]
    assert tt.r == pytest.approx((scores["TT y"].r + o.r) / 2)
    assert tt.rmse_mm == pytest.approx(np.sqrt((170 * scores["TT y"].rmse_mm ** 2 + o.frames * o.rmse_mm ** 2)
                                               / (170 + o.frames)))
    moving = [r for r in table.rows if r.sensor != "REF"]
    assert table.mean_rmse_mm == pytest.approx(np.mean([r.rmse_mm for r in moving]))


# ---------------------------------------------------------------------- eval on EMA corpora
@pytest.fixture(scope="module")
def ema_corpora(tmp_path_factory):
    """The MOCHA sample as a corpus (2-D, its own coils) and an MVIEW file made from it (3-D,
    HPRC's sensors), each with its model (one utterance: train only)."""
    if not (MOCHA / "fsew0_001.ema").exists():
        pytest.skip("the MOCHA sample ../shared/data/mocha_fsew0_001 is absent")
    root = tmp_path_factory.mktemp("ema")
    mocha, _ = init_corpus(MOCHA, root / "mocha" / "corpus.json", ["UI", "BN"], "UL", "LL",
                           label_map="mocha", test_fraction=0)
    mview = mview_from_mocha(MOCHA, root / "mview").parent
    init_corpus(mview, upper_lip="UL", lower_lip="LL", test_fraction=0)
    out = {}
    for name, path in (("mocha", mocha), ("mview", mview / "corpus.json")):
        assert main(["-q", "train", str(path), "-o", str(root / f"{name}.npz"), "--no-tune"]) == 0
        out[name] = (path, root / f"{name}.npz")
    return out


@pytest.mark.parametrize("which, sensors, axes", [
    ("mocha", ["LI", "UL", "LL", "TT", "TB", "TD", "V"], "yz"),
    ("mview", ["TR", "TB", "TT", "UL", "LL", "ML", "JAW", "JAWL"], "yz"),
])
def test_eval_json_lists_every_sensor_coordinate(ema_corpora, which, sensors, axes, capsys):
    """The aim: ``eval --json`` on a MOCHA or an MVIEW corpus lists r and RMSE (mm) of every
    sensor coordinate, the baselines' too; checked against numpy on the synthesis."""
    from facetraj_engine.config import SynthConfig
    from facetraj_engine.method.pipeline import resmooth, synthesize
    from facetraj_engine.method.speech import speech_mask

    corpus_path, model_path = ema_corpora[which]
    assert main(["-q", "eval", str(model_path), str(corpus_path), "--json", "-j", "1"]) == 0
    out = json.loads(capsys.readouterr().out)
    table = next(t for t in out["sensors"] if t["smoothing"] == "triangular")
    rows = {f"{c['sensor']} {c['axis']}": c for c in table["coordinates"]}
    assert {f"{s} {a}" for s in sensors for a in axes} <= set(rows)
    assert all(np.isfinite([c["r"], c["rmse_mm"]]).all() and c["frames"] > 60 for c in rows.values())
    assert set(rows) <= {f"{s} {a}" for s in (*sensors, "UI", "BN") for a in "xyz"}
    # numpy on the synthesis eval made (its mode by the labels, triangular smoothing)
    model, utt = Model.load(model_path), load_corpus(corpus_path).utterance("fsew0_001")
    cfg = SynthConfig(mode=table["mode"])
    res = synthesize(model, utt.audio, utt.sample_rate, utt.phones, cfg, n_frames=utt.n_frames,
                     source=utt.name, confidence=utt.confidence, provenance=utt.provenance)
    syn, orig = resmooth(model, res, "triangular"), model.normalise_markers(utt.markers)
    mask = speech_mask(utt.audio, utt.sample_rate, res.times)
    for key in ("TT y", "TB z", "LL y"):
        m, a = model.marker_names.index(key.split()[0]), "xyz".index(key[-1])
        ok = mask & np.isfinite(orig[:, m, a])
        assert rows[key]["r"] == pytest.approx(np.corrcoef(orig[ok, m, a], syn[ok, m, a])[0, 1], abs=1e-9)
        assert rows[key]["rmse_mm"] == pytest.approx(
            np.sqrt(np.mean((orig[ok, m, a] - syn[ok, m, a]) ** 2)), abs=1e-9)
    # the paper's three correlations beside them, the baselines in the same layout
    assert out["table"][0]["lower_lip"] == pytest.approx(
        np.corrcoef(orig[ok, model.lower_lip, 1], syn[ok, model.lower_lip, 1])[0, 1], abs=1e-9)
    modes = {t["mode"] for t in out["baselines"]["sensors"]}
    assert modes == {"viseme", "ridge"}
    base = next(t for t in out["baselines"]["sensors"] if t["mode"] == "ridge")
    assert {f"{c['sensor']} {c['axis']}" for c in base["coordinates"]} == set(rows)


def test_eval_prints_the_per_sensor_table(ema_corpora, capsys):
    corpus_path, model_path = ema_corpora["mview"]
    assert main(["-q", "eval", str(model_path), str(corpus_path), "-j", "1"]) == 0
    text = capsys.readouterr().out
    head = next(i for i, ln in enumerate(text.splitlines()) if ln.startswith("sensor"))
    lines = text.splitlines()
    assert lines[head].split()[2:] == ["robust", "N=3", "viseme", "ridge"]
    assert lines[head + 2].startswith("whole face (r)")
    tt = next(ln for ln in lines if ln.startswith("TT y"))
    assert tt.split()[2] == "tongue" and len(tt.split()) == 3 + 2 * 3
    assert lines[-1].startswith("articulators (mean)")
    assert main(["-q", "eval", str(model_path), str(corpus_path), "-j", "1", "--no-baselines"]) == 0
    assert "ridge" not in capsys.readouterr().out


def test_model_keeps_the_sensor_roles(ema_corpora, tmp_path):
    corpus_path, _ = ema_corpora["mview"]
    obj = json.loads(corpus_path.read_text())
    obj["sensor_roles"] = {"tongue": ["TT", "TB"], "other": ["TR"]}
    (tmp_path / "corpus.json").write_text(json.dumps({**obj, "data_dir": str(corpus_path.parent)}))
    assert main(["-q", "train", str(tmp_path), "-o", str(tmp_path / "m.npz"), "--no-tune"]) == 0
    model = Model.load(tmp_path / "m.npz")
    assert model.sensor_roles == {"tongue": ["TT", "TB"], "other": ["TR"]}
    assert named(model.roles, "tongue") == ["TT", "TB"] and model.roles.role(0) == "other"
    # a model file whose roles name no sensor of it is refused
    from conftest import edited_model_file

    with np.load(tmp_path / "m.npz", allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
    meta["sensor_roles"] = {"tongue": ["T9"]}
    bad = edited_model_file(tmp_path / "m.npz", tmp_path / "bad.npz", meta=np.array(json.dumps(meta)))
    with pytest.raises(ModelFileError, match="'sensor_roles' names 'T9', not among marker_names"):
        Model.load(bad)


def test_measures_of_the_articulators(ema_corpora):
    """Tongue tip height, lip aperture and jaw opening of a frame, against the markers."""
    model = Model.load(ema_corpora["mocha"][1])
    utt = load_corpus(ema_corpora["mocha"][0]).utterance("fsew0_001")
    pts = model.normalise_markers(utt.markers)[60]
    top = jaw_top(model)
    names = model.marker_names
    a = measure(pts, model.roles, top)
    assert a.tongue_tip == pts[names.index("TT"), 1]
    assert a.aperture == pytest.approx(np.linalg.norm(pts[names.index("UL")] - pts[names.index("LL")]))
    assert a.jaw_opening == pytest.approx(top - pts[names.index("LI"), 1])
    # the top is the 95th percentile of the jaw's height over the codewords: most are below it
    faces = model.to_markers(model.codebook.pcs)[:, names.index("LI"), 1]
    assert np.mean(faces <= top) == pytest.approx(0.95, abs=0.02)
