"""The TextGrid reader (engine/io/textgrid.py) against praatio, an independent implementation:
the same tiers from files praatio writes in the long and the short text forms, and a clear
refusal, naming the place, of text that is not a TextGrid."""

import itertools

import numpy as np
import pytest
from praatio import textgrid as ptg

from facetraj_engine.errors import InputError
from facetraj_engine.io.labelfiles import read_textgrid_tiers
from facetraj_engine.io.textgrid import TextGridSyntaxError, parse_textgrid

LABELS = ["sil", "", 'say "ah"', "é ʃ ŋ", "a = b : [1]", "two\nlines", "12.5", "<exists>"]


def _praatio_file(tmp_path, form: str):
    rng = np.random.default_rng(7)
    tg = ptg.Textgrid()
    times = np.round(np.cumsum(rng.uniform(0.01, 0.3, 41)), 4)
    entries = [(float(a), float(b), LABELS[i % len(LABELS)])
               for i, (a, b) in enumerate(itertools.pairwise(times))]
    tg.addTier(ptg.IntervalTier("phones", entries, 0.0, float(times[-1])))
    tg.addTier(ptg.PointTier("events", [(0.5, "click"), (1.25, "")], 0.0, float(times[-1])))
    tg.addTier(ptg.IntervalTier("words", entries[::3], 0.0, float(times[-1])))
    path = tmp_path / f"{form}.TextGrid"
    tg.save(str(path), format=form, includeBlankSpaces=True)
    return path


@pytest.mark.parametrize("form", ["long_textgrid", "short_textgrid"])
def test_the_tiers_praatio_reads(tmp_path, form):
    path = _praatio_file(tmp_path, form)
    theirs = ptg.openTextgrid(str(path), includeEmptyIntervals=True)
    ours = parse_textgrid(path.read_text(encoding="utf-8"))
    assert [t.name for t in ours] == list(theirs.tierNames) == ["phones", "events", "words"]
    assert [t.kind for t in ours] == ["IntervalTier", "TextTier", "IntervalTier"]
    for tier in ours:
        want = [tuple(e) for e in theirs.getTier(tier.name).entries]
        assert len(tier.entries) == len(want) > 0
        for got, ref in zip(tier.entries, want, strict=True):
            assert got[:-1] == pytest.approx(ref[:-1], abs=1e-12)
            assert got[-1] == ref[-1]
    labels = [e[2] for e in ours[0].entries]
    assert 'say "ah"' in labels and "two\nlines" in labels and "" in labels


def test_utf16_as_praat_writes_it(tmp_path):
    path = _praatio_file(tmp_path, "long_textgrid")
    utf16 = tmp_path / "utf16.TextGrid"
    utf16.write_bytes(path.read_text(encoding="utf-8").encode("utf-16"))
    assert "é ʃ ŋ" in [s.label for s in read_textgrid_tiers(utf16)["phones"]]


@pytest.mark.parametrize("text, where", [
    ('File type = "ooTextFile"\nObject class = "Sound"\n', "not a TextGrid text file"),
    ('File type = "ooTextFile"\nObject class = "TextGrid"\n0\n1\n<exists>\n1\n"IntervalTier"\n'
     '"phones"\n0\n1\n2\n0\n0.5\n"a"\n0.5\n', "the text ends where tier 'phones': interval 2's end"),
    ('File type = "ooTextFile"\nObject class = "TextGrid"\n0\n1\n<exists>\n1\n"IntervalTier"\n'
     '"phones"\n0\n1\n1\n0\nnan\n"a"\n', "expected tier 'phones': interval 1's end, found 'a'"),
    ('File type = "ooTextFile"\nObject class = "TextGrid"\n0\n1\n<exists>\n1.5\n',
     "the number of tiers is not a count"),
    ('File type = "ooTextFile"\nObject class = "TextGrid"\n0\n1\n<exists>\n1\n"Tier"\n"x"\n0\n1\n0\n',
     "class 'Tier'"),
    ('File type = "ooTextFile"\nObject class = "TextGrid"\n0\n1e999\n', "not a finite number"),
    ("", "the file type"),
    ('File type = "ooTextFile"\nObject class = "TextGrid"\n"0\n' + "x" * 5000 + '"\n',
     "expected the start time, found '0\\n" + "x" * 38 + "...'"),
])
def test_what_is_not_a_textgrid_is_refused_with_its_place(text, where):
    with pytest.raises(TextGridSyntaxError) as err:
        parse_textgrid(text)
    assert where in str(err.value)


def test_the_label_reader_names_the_file(tmp_path):
    bad = tmp_path / "bad.TextGrid"
    bad.write_text('File type = "ooTextFile"\nObject class = "TextGrid"\n0\n')
    with pytest.raises(InputError, match="bad.TextGrid.*not a readable TextGrid .*end time"):
        read_textgrid_tiers(bad)
    assert parse_textgrid('File type = "ooTextFile"\nObject class = "TextGrid"\n0\n1\n<absent>\n') == []


@pytest.mark.parametrize("damage, where", [
    ("xmin = 0.4", "xmin = 0.4O5"),          # a letter in a number: not read as 0.4
    ("xmax = 0.4", "xmax = 0.4m"),
    ("xmin = 0.4", "xmin |= 0.4"),           # a stray character between the values
])
def test_a_damaged_token_is_refused_not_guessed(tmp_path, damage, where):
    path = _praatio_file(tmp_path, "long_textgrid")
    text = path.read_text(encoding="utf-8")
    assert damage in text
    bad = text.replace(damage, where, 1)
    with pytest.raises(TextGridSyntaxError):
        parse_textgrid(bad)
    with pytest.raises(TextGridSyntaxError, match="after the last tier"):
        parse_textgrid(text + "\n1.5\n")
