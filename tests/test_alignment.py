"""Phone labels for a recording: forced alignment, phone recognition, the label-source rule, the
label cache, boundary accuracy, and the ``align`` / ``synth --text`` / ``corpus align`` commands.

The clips are real data: sentences of the default corpus (articulatory-synthesized speech with
exact labels) and, when ../shared is present, the real MOCHA-TIMIT recording with hand labels.
"""

import shutil

import numpy as np
import pytest
from conftest import DEFAULT_CORPUS, MOCHA

from facetraj_engine.data import PhoneSegment
from facetraj_engine.evaluation.label_accuracy import boundary_errors, merged, phone_error_rate, summarise
from facetraj_engine.io.audio import read_audio
from facetraj_engine.io.labelfiles import read_lab, read_textgrid, read_textgrid_tiers, recorded_provenance
from facetraj_engine.io.labelling import label_audio, label_corpus, labels_for_audio, relabelled
from facetraj_engine.labels.alignment import MissingWordsError, UnalignableError, align, recognize
from facetraj_engine.labels.labelmap import read_label_map
from facetraj.cli import main

CLIP = DEFAULT_CORPUS / "s002.flac"        # "The boy enjoyed the noisy toy." 2.1 s


@pytest.fixture(scope="module")
def clip():
    audio, rate = read_audio(CLIP)
    return audio, rate, read_textgrid(CLIP.with_suffix(".TextGrid")), \
        CLIP.with_suffix(".txt").read_text().strip()


@pytest.fixture(scope="module")
def clip_aligned(clip):
    audio, rate, _, text = clip
    return align(audio, rate, text, source=CLIP)


def test_alignment_recovers_the_phones_in_order_near_the_truth(clip, clip_aligned):
    audio, rate, truth, _ = clip
    lab = clip_aligned
    assert lab.source == "aligned"
    # the same phones in order, but for the dictionary's vowel of "enjoyed" (ih; the corpus: eh)
    hyp = [p.label for p in lab.phones if p.label != "sil"]
    ref = [p.label for p in truth if p.label != "sil"]
    assert len(hyp) == len(ref) and [i for i, (a, b) in enumerate(zip(hyp, ref, strict=True))
                                     if a != b] == [4] and (hyp[4], ref[4]) == ("ih", "eh")
    assert [w.label for w in lab.words] == ["the", "boy", "enjoyed", "the", "noisy", "toy"]
    assert lab.phones[0].start == 0.0 and lab.phones[-1].end == pytest.approx(len(audio) / rate)
    err = np.abs(boundary_errors(merged(truth), lab.phones))
    assert err.size == len(truth) - 1
    assert np.median(err) < 0.015 and np.mean(err <= 0.02) > 0.7 and err.max() < 0.06
    # the /b/ of "boy": its closure onset (the lips) within 20 ms of the truth
    b_true = next(p for p in truth if p.label == "b")
    b_hyp = next(p for p in lab.phones if p.label == "b")
    assert abs(b_hyp.start - b_true.start) < 0.02


def test_alignment_scores(clip_aligned):
    lab = clip_aligned
    speech = np.array([p.label != "sil" for p in lab.phones])
    assert np.all(np.isfinite(lab.scores)) and np.all(lab.scores <= 0)
    assert np.all((lab.confidence > 0) & (lab.confidence <= 1))
    # a correct sentence fits its phones: the median phone scores better than -25 per frame
    assert np.median(lab.scores[speech]) > -25


@pytest.mark.skipif(not MOCHA.exists(), reason="../shared/data/mocha_fsew0_001 not present")
def test_real_recording_against_hand_labels():
    audio, rate = read_audio(MOCHA / "fsew0_001.wav")
    hand = merged(read_lab(MOCHA / "fsew0_001.lab"), read_label_map("mocha"))
    lab = align(audio, rate, "This was easy for us.")
    assert [p.label for p in lab.phones] == "sil dh ih s w ah z iy z iy f ao r ah s sil".split()
    acc = summarise("aligned", [(hand, lab.phones)])
    assert acc.boundaries == 15 and acc.median_error_ms <= 15 and acc.within_20ms >= 0.8
    errors = {}
    for ph in ("w", "f"):   # the lip phones of the sentence (measured: w 10 ms, f 40 ms early)
        t_hand = next(p.start for p in hand if p.label == ph)
        errors[ph] = next(p.start for p in lab.phones if p.label == ph) - t_hand
    assert abs(errors["w"]) <= 0.02 + 1e-9 and abs(errors["f"]) <= 0.05
    rec = recognize(audio, rate)
    assert rec.source == "recognized" and rec.words == []
    f_hand = next(p for p in hand if p.label == "f")
    f_rec = [p for p in rec.phones if p.label == "f"]
    assert any(abs(p.start - f_hand.start) <= 0.05 + 1e-9 for p in f_rec)    # measured 50 ms
    edits, n = phone_error_rate(hand, rec.phones)
    assert n == 14 and edits / n < 0.6


def test_recognition_of_the_clip(clip):
    audio, rate, truth, _ = clip
    rec = recognize(audio, rate, CLIP)
    acc = summarise("recognized", [(truth, rec.phones)])
    assert 0.0 < acc.per < 0.8 and acc.boundaries > 5 and acc.median_error_ms < 40
    assert np.isfinite(rec.scores).sum() >= len(rec.phones) - 2


def test_resampled_input_aligns_the_same(clip, clip_aligned):
    from scipy.signal import resample_poly

    audio, rate, _, text = clip
    lab = align(resample_poly(audio, 3, 1), rate * 3, text)      # 48 kHz
    assert [p.label for p in lab.phones] == [p.label for p in clip_aligned.phones]
    err = np.abs([a.start - b.start for a, b in zip(lab.phones, clip_aligned.phones, strict=True)])
    assert err.max() <= 0.02


def test_missing_words_are_named_and_can_be_added(clip):
    audio, rate, _, _ = clip
    with pytest.raises(MissingWordsError) as exc:
        align(audio, rate, "the boy enjoyed the zorblax qwertyz toy", source=CLIP)
    assert exc.value.words == ["zorblax", "qwertyz"]
    assert "s002.flac: not in the pronouncing dictionary: zorblax, qwertyz" in str(exc.value)
    # "noisy" spelt oddly, with its pronunciation given
    lab = align(audio, rate, "the boy enjoyed the noizee toy",
                extra_dict={"noizee": ["n", "oy", "z", "iy"]})
    assert [w.label for w in lab.words][4] == "noizee"


def test_unalignable_and_empty_text(clip):
    audio, rate, _, _ = clip
    with pytest.raises(UnalignableError, match="does not match the audio"):
        align(audio, rate, "tornadoes often destroy acres of farm land")
    with pytest.raises(UnalignableError, match="does not match the audio"):
        align(audio, rate, "measure the beige garage with care")      # same length, wrong words
    with pytest.raises(UnalignableError, match="silent"):
        align(np.zeros(rate), rate, "the boy")
    with pytest.raises(UnalignableError, match="too long"):
        align(audio[: rate // 2], rate, text := "the boy enjoyed the noisy toy")
    assert text
    with pytest.raises(Exception, match="the text is empty"):
        align(audio, rate, " ,. ")


def test_label_source_rule(tmp_path, clip):
    audio, rate, truth, text = clip
    wav = tmp_path / "u.flac"
    shutil.copy(CLIP, wav)
    assert labels_for_audio(wav, audio, rate) is None                       # -> acoustic-only
    (tmp_path / "u.txt").write_text(text)
    assert labels_for_audio(wav, audio, rate).source == "aligned"            # .txt beside
    shutil.copy(CLIP.with_suffix(".TextGrid"), tmp_path / "u.TextGrid")
    beside = labels_for_audio(wav, audio, rate)                              # label file beside
    assert beside.source == "file" and [p.label for p in beside.phones] == [p.label for p in truth]
    assert labels_for_audio(wav, audio, rate, recognize=True).source == "recognized"
    assert labels_for_audio(wav, audio, rate, text="the boy enjoyed the noisy toy").source == "aligned"


def test_label_cache(tmp_path, monkeypatch, clip):
    audio, rate, _, text = clip
    monkeypatch.setenv("FACETRAJ_CACHE_DIR", str(tmp_path))
    first = label_audio(audio, rate, "aligned", text)
    assert len(list((tmp_path / "labels").glob("labels-*.json"))) == 1
    import facetraj_engine.io.labelling as labelling

    monkeypatch.setattr(labelling, "align", lambda *a, **k: pytest.fail("not cached"))
    again = label_audio(audio, rate, "aligned", text)
    assert again.phones == first.phones and np.allclose(again.scores, first.scores)
    assert again.words == first.words and again.source == "aligned"


def test_relabelled_corpus(toy_corpus, monkeypatch, tmp_path):
    """Every utterance labelled; the relabelled corpus trains and evaluates like any corpus."""
    from facetraj_engine.labels.provenance import Labels

    calls = []

    def fake(audio, rate, method, text="", extra_dict=None, source=None, use_cache=True):
        calls.append(method)
        dur = len(audio) / rate
        return Labels([PhoneSegment(0, dur / 2, "sil"), PhoneSegment(dur / 2, dur, "aa")],
                      source=method)

    import facetraj_engine.io.labelling as labelling

    monkeypatch.setattr(labelling, "label_audio", fake)
    auto = label_corpus(toy_corpus, "aligned")
    assert set(auto.labels) == set(toy_corpus.info.ids) and not auto.failed
    assert set(calls) == {"recognized"}          # the toy corpus has no transcripts
    rc = relabelled(toy_corpus, "recognized")
    utt = rc.utterance(toy_corpus.info.test[0])
    assert [p.label for p in utt.phones] == ["sil", "aa"]
    assert rc.fingerprint() != toy_corpus.fingerprint()


def test_boundary_error_hand_example():
    ref = [PhoneSegment(0, .10, "sil"), PhoneSegment(.10, .20, "b"), PhoneSegment(.20, .30, "iy"),
           PhoneSegment(.30, .40, "sil")]
    hyp = [PhoneSegment(0, .12, "sil"), PhoneSegment(.12, .20, "p"), PhoneSegment(.20, .27, "iy"),
           PhoneSegment(.27, .30, "t"), PhoneSegment(.30, .40, "sil")]
    # matched: sil-sil, b-p (substitution), iy-iy; "t" inserted, so the final sil is not scored
    assert boundary_errors(ref, hyp).round(3).tolist() == [0.02, 0.0]
    assert phone_error_rate(ref, hyp) == (2, 2)
    acc = summarise("x", [(ref, hyp)])
    assert acc.boundaries == 2 and acc.median_error_ms == pytest.approx(10.0)
    assert acc.within_20ms == 1.0 and acc.per == 1.0


# --------------------------------------------------------------------------- commands
def test_align_command_writes_a_textgrid(tmp_path, clip):
    _, _, truth, text = clip
    out = tmp_path / "a.TextGrid"
    assert main(["-q", "align", str(CLIP), "--text", text, "-o", str(out)]) == 0
    tiers = read_textgrid_tiers(out)
    assert list(tiers) == ["words", "phones", "provenance", "confidence"]
    assert tiers["provenance"][0].label.startswith("source=aligned; tool=PocketSphinx ")
    assert tiers["provenance"][0].label.endswith("; from=the sentence given")
    assert len([p for p in tiers["phones"] if p.label not in ("", "sil")]) == \
        len([p for p in truth if p.label != "sil"])
    assert main(["-q", "align", str(CLIP), "--text", text, "-o", str(out)]) == 2   # exists
    (tmp_path / "t.txt").write_text(text)
    assert main(["-q", "align", str(CLIP), "--transcript", str(tmp_path / "t.txt"), "-o",
                 str(out), "--overwrite"]) == 0
    rec = tmp_path / "r.TextGrid"
    assert main(["-q", "align", str(CLIP), "--recognize", "-o", str(rec)]) == 0
    assert list(read_textgrid_tiers(rec)) == ["phones", "provenance", "confidence"]
    assert recorded_provenance(rec).kind == "recognized"


@pytest.mark.parametrize("args, message", [
    (["--text", "the boy enjoyed the zorblax toy"], "not in the pronouncing dictionary: zorblax"),
    (["--text", "tornadoes often destroy acres of farm land"], "does not match the audio"),
    (["--text", ""], "the text is empty"),
    (["--text", "le garçon aimé ß"], "non-English characters (ß)"),
])
def test_align_command_bad_input(tmp_path, capsys, args, message):
    out = tmp_path / "x.TextGrid"
    assert main(["-q", "align", str(CLIP), *args, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("facetraj: error: ") and message in err and "s002.flac" in err
    assert not out.exists() and not list(tmp_path.iterdir())        # nothing written


def test_align_command_dict(tmp_path, capsys):
    d = tmp_path / "extra.dict"
    d.write_text(";;; my words\nNOIZEE  N OY1 Z IY0\n")
    out = tmp_path / "a.TextGrid"
    assert main(["-q", "align", str(CLIP), "--text", "the boy enjoyed the noizee toy",
                 "--dict", str(d), "-o", str(out)]) == 0
    assert "noizee" in [w.label for w in read_textgrid_tiers(out)["words"]]


def test_synth_with_text_aligns_then_synthesizes_robustly(tmp_path, default_model, caplog):
    """Aligned labels are not hand-checked: synth picks the robust mode (issue 16), or the
    paper's phonetic mode when asked for explicitly."""
    import logging

    model = default_model.save(tmp_path / "m.npz")
    wav = tmp_path / "u.flac"
    shutil.copy(CLIP, wav)
    text = CLIP.with_suffix(".txt").read_text()
    with caplog.at_level(logging.INFO, logger="facetraj"):
        assert main(["synth", str(model), str(wav), "-o", str(tmp_path / "a.c3d")]) == 0
    assert "labels recognized from u.flac" in caplog.text     # nothing beside it: recognition
    assert "; robust mode: recognized labels are not hand-checked" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="facetraj"):
        assert main(["synth", str(model), str(wav), "--mode", "acoustic",
                     "-o", str(tmp_path / "b.c3d")]) == 0
    assert "labels none; acoustic-only (indexed) mode: chosen" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="facetraj"):
        assert main(["synth", str(model), str(wav), "--text", text,
                     "-o", str(tmp_path / "p.c3d")]) == 0
    assert "labels aligned from the sentence given (PocketSphinx" in caplog.text
    assert "; robust mode: aligned labels are not hand-checked" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="facetraj"):
        assert main(["synth", str(model), str(wav), "--text", text, "--mode", "phonetic",
                     "-o", str(tmp_path / "x.c3d")]) == 0
    assert "; phonetic mode: chosen, although the labels are aligned" in caplog.text
    (tmp_path / "u.txt").write_text(text)                  # the .txt beside is used
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="facetraj"):
        assert main(["synth", str(model), str(wav), "-o", str(tmp_path / "t.c3d")]) == 0
    assert "labels aligned from u.txt (PocketSphinx" in caplog.text
    assert "; robust mode: aligned labels are not hand-checked" in caplog.text
    from facetraj_engine.io.markerfiles import read_c3d

    a, p, t = (read_c3d(tmp_path / f"{n}.c3d").markers for n in "apt")
    np.testing.assert_allclose(p, t)                        # same labels, same trajectories
    assert not np.allclose(a, p)


def test_corpus_align_command(tmp_path, caplog):
    import logging

    for stem in ("s001", "s002", "s003"):
        shutil.copy(DEFAULT_CORPUS / f"{stem}.flac", tmp_path)
    shutil.copy(DEFAULT_CORPUS / "s001.txt", tmp_path)
    (tmp_path / "s002.txt").write_text("the boy enjoyed the zorblax toy")
    caplog.set_level(logging.INFO)
    assert main(["corpus", "align", str(tmp_path)]) == 0
    assert "3 TextGrids written (1 aligned, 2 recognized), 0 existing kept" in caplog.text
    assert "recognized instead: s002: not in the pronouncing dictionary: zorblax" in caplog.text
    words = read_textgrid_tiers(tmp_path / "s001.TextGrid")["words"]
    assert [w.label for w in words if w.label][:2] == ["tornadoes", "often"]
    before = (tmp_path / "s001.TextGrid").read_bytes()
    caplog.clear()
    assert main(["corpus", "align", str(tmp_path), "--recognize"]) == 0
    assert "0 TextGrids written (0 aligned, 0 recognized), 3 existing kept" in caplog.text
    assert (tmp_path / "s001.TextGrid").read_bytes() == before
    caplog.clear()
    assert main(["corpus", "align", str(tmp_path), "--recognize", "--overwrite"]) == 0
    assert "3 TextGrids written (0 aligned, 3 recognized)" in caplog.text
    assert list(read_textgrid_tiers(tmp_path / "s001.TextGrid")) == ["phones", "provenance",
                                                                     "confidence"]
    assert main(["corpus", "align", str(tmp_path / "nowhere")]) == 2


def test_report_section_renders_the_accuracy_table(clip, clip_aligned):
    from facetraj_engine.report.labels import render_section

    _, _, truth, _ = clip
    row = {"data": "clip (exact labels)", **summarise("aligned", [(truth, clip_aligned.phones)]).to_json()}
    t2 = {"trained_on": "aligned", "tested_on": "recognized", "split": "test",
          "smoothing": "triangular", "whole_face": 0.5, "lower_lip": 0.4, "upper_lip": 0.3,
          "whole_face_std": 0.1, "lower_lip_std": float("nan"), "upper_lip_std": 0.1, "n": 3}
    md = render_section({"pocketsphinx": "5.1.1", "accuracy": [row], "table2": [t2]})
    line = next(x for x in md if x.startswith("| clip"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[:4] == ["clip (exact labels)", "aligned", "1", str(row["boundaries"])]
    assert float(cells[4]) == pytest.approx(row["median_error_ms"], abs=0.05)
    assert "| aligned | recognized | test | triangular | 0.500 ± 0.100 | 0.400 | 0.300 ± 0.100 | 3 |" in md


def test_labelling_benchmark_smoke():
    """The benchmark's rows are there with positive finite numbers (no timing threshold)."""
    import math

    from benchmarks.common import load_context
    from benchmarks.labels import run

    rows = run(load_context(DEFAULT_CORPUS, smoke=True))
    assert [r.name for r in rows] == ["align, per second of speech",
                                      "align, no fit check, per second of speech",
                                      "recognize, per second of speech"]
    assert all(math.isfinite(r.value) and r.value > 0 and r.unit == "s/s" for r in rows)
