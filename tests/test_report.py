"""The results report (issue 7): ``facetraj_app.report_figures.make_report`` on a small toy corpus writes
every section, the JSON of all numbers and non-blank figures."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from toycorpus import build_toy_corpus

from facetraj_engine.evaluation.paper import FIGURE4_TEXT, PAPER_TABLE2, paper_table1
from facetraj_engine.method.similarity import SimilarRow
from facetraj_engine.report import find_utterance, table1_agreement

SECTIONS = (
    "## Table 2: correlation, original vs synthesized (N = 3)",
    "## Figure 5: correlation against N",
    "## Figure 4: an example",
    "## Comparisons on the same split",
    "## Per sensor",
    "## Table 1: the three visually most similar phones",
    "## Discussion: where and why we differ from the paper",
    "## Reproducing",
)


@pytest.fixture(scope="module")
def small_corpus(tmp_path_factory) -> Path:
    root = build_toy_corpus(tmp_path_factory.mktemp("toy-report"), n_train=8, n_test=3, seed=3)
    from facetraj_engine.io.corpus import load_corpus

    test_id = load_corpus(root).info.test[1]
    (root / f"{test_id}.txt").write_text(FIGURE4_TEXT + ".\n", encoding="utf-8")
    return root


@pytest.fixture(scope="module")
def report(small_corpus, tmp_path_factory) -> Path:
    from facetraj_app.report_figures import make_report

    out = tmp_path_factory.mktemp("docs")
    seen = []
    md = make_report(small_corpus, out, ns=(1, 2), progress=lambda f, m: seen.append(f))
    assert seen and seen[-1] == pytest.approx(1.0)
    assert all(0 <= f <= 1 for f in seen)
    return md


def test_markdown_has_every_section(report: Path, small_corpus: Path) -> None:
    assert report.name == "results.md"
    text = report.read_text()
    for heading in SECTIONS:
        assert heading in text, heading
    # the paper's numbers beside ours
    for value in ("0.9239", "0.7338", "0.8468", "0.7230"):
        assert value in text
    for method in ("phonetic (N = 3)", "acoustic-only", "acoustic-only, indexed", "viseme lookup",
                   "ridge regression"):
        assert method in text
    # the paper's sentence was found (test split) and named
    assert f'"{FIGURE4_TEXT}.' in text and "not in the corpus" not in text
    for name in ("figure4", "figure5", "comparison"):
        assert f"(figures/results_{name}.png)" in text


def test_per_sensor_section(report: Path) -> None:
    """r and RMSE (mm) per sensor coordinate for each method, the baselines beside the paper's
    method; a long table cut to the coordinates that move most (all of them in the JSON)."""
    data = json.loads((report.parent / "results.json").read_text())["sensors"]
    assert data["split"] == "test" and [m["method"] for m in data["methods"]] == [
        "phonetic (N = 3)", "acoustic-only", "acoustic-only, indexed", "viseme lookup",
        "ridge regression"]
    keys = [f"{c['sensor']} {c['axis']}" for c in data["methods"][0]["coordinates"]]
    assert "LL_C y" in keys and "UL_C y" in keys and len(keys) > 15
    for m in data["methods"]:
        assert [f"{c['sensor']} {c['axis']}" for c in m["coordinates"]] == keys
        assert all(0 < c["rmse_mm"] < 50 and -1 <= c["r"] <= 1 for c in m["coordinates"])
    text = report.read_text()
    section = text[text.index("## Per sensor"):].split("\n## ")[0]
    rows = [ln for ln in section.splitlines() if ln.startswith("| ") and not ln.startswith("| Coord")]
    most = sorted(keys, key=lambda k: -data["sd_mm"][k])[:15]
    assert [r.split(" | ")[0][2:] for r in rows[:-1]] == most
    assert rows[-1].startswith("| articulators (mean)")
    ll = next(c for c in data["methods"][0]["coordinates"] if c["sensor"] == "LL_C" and c["axis"] == "y")
    if "LL_C y" in most:
        assert f"{ll['r']:.3f} / {ll['rmse_mm']:.2f}" in section


def test_json_holds_all_numbers(report: Path) -> None:
    data = json.loads((report.parent / "results.json").read_text())
    assert {r["split"] + "/" + r["smoothing"] for r in data["table2"]} == {
        "train/triangular", "train/spline", "test/triangular", "test/spline"}
    for r in data["table2"]:
        for m in ("whole_face", "lower_lip", "upper_lip"):
            assert -1 <= r[m] <= 1
    modes = {r["mode"] for r in data["comparisons"]}
    assert modes == {"phonetic", "acoustic", "acoustic-indexed", "viseme", "ridge"}
    assert data["sweep"]["ns"] == [1, 2]
    assert len(data["sweep"]["test"]["whole_face"]) == 2
    assert data["figure4"]["found"] and data["figure4"]["split"] == "test"
    assert len(data["table1"]) == 7                      # the toy's phones except silence
    assert len(data["paper_table2"]) == 4


@pytest.mark.parametrize("name", ["figure4", "figure5", "comparison"])
def test_figures_are_non_blank_images(report: Path, name: str) -> None:
    import matplotlib.image as mpimg

    path = report.parent / "figures" / f"results_{name}.png"
    assert path.exists()
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[0] > 200 and img.shape[1] > 400
    rgb = img[..., :3]
    assert float(rgb.std()) > 0.05
    assert float((rgb.mean(axis=2) < 0.9).mean()) > 0.01     # more than 1 % of the pixels drawn


def test_only_report_files_are_written(report: Path) -> None:
    files = sorted(p.relative_to(report.parent).as_posix() for p in report.parent.rglob("*")
                   if p.is_file())
    assert files == ["figures/results_comparison.png", "figures/results_figure4.png",
                     "figures/results_figure5.png", "results.json", "results.md"]


def test_find_utterance_and_paper_tables(small_corpus: Path) -> None:
    from facetraj_engine.io.corpus import load_corpus

    corpus = load_corpus(small_corpus)
    assert find_utterance(corpus) == (corpus.info.test[1], "test")
    assert find_utterance(corpus, "no such sentence anywhere") is None
    paper = paper_table1()
    assert len(paper) == 41
    assert paper["b"][0] == ("p", 0.78) and paper["uh"][0][0] == "uw"   # quoted in section 2.2
    assert PAPER_TABLE2[("test", "triangular")][0] == 0.7338
    rows = [SimilarRow("b", (("p", 0.9), ("m", 0.5), ("aa", 0.1))),
            SimilarRow("m", (("b", 0.9), ("f", 0.5), ("v", 0.1)))]
    agree = table1_agreement(rows, paper)
    assert agree.phones_compared == 2 and agree.same_closest == 1
    assert math.isclose(agree.mean_top3_overlap, (2 + 1) / 2)


def test_engine_report_does_not_plot() -> None:
    import facetraj_engine.report

    for path in Path(facetraj_engine.report.__file__).parent.glob("*.py"):
        src = path.read_text()
        assert "import matplotlib" not in src and "from matplotlib" not in src, path  # pure engine
