"""The label document (engine/labels/editing.py): every edit on hand-checked examples, refusals
that change nothing, undo/redo, the dirty flag, and which phones count as checked by hand (the
same as a TextGrid saved and read back says)."""

from __future__ import annotations

import numpy as np
import pytest

from facetraj_engine.data import PhoneSegment as S
from facetraj_engine.data import Provenance
from facetraj_engine.io.labelfiles import read_label_file
from facetraj_engine.io.labelling import write_labels
from facetraj_engine.labels.editing import PHONES, WORDS, EditRefused, LabelDocument, Selection
from facetraj_engine.labels.provenance import Labels

RATE = 60.0     # frames 16.7 ms apart


def recognized(phones, conf=None, words=()) -> Labels:
    conf = np.full(len(phones), 0.5) if conf is None else np.asarray(conf, float)
    return Labels([S(*p) for p in phones], [S(*w) for w in words], "recognized",
                  scores=10.0 * np.log(conf), provenance=Provenance("recognized", "PocketSphinx 5.1.1"))


#: "I'm glad": the /m/ of "I'm" heard as /n/ (axb_a0004's error)
IM_GLAD = [(0.0, 0.2, "sil"), (0.2, 0.5, "ay"), (0.5, 0.6, "n"), (0.6, 0.7, "g"), (0.7, 1.0, "l")]


def doc(phones=IM_GLAD, **kw) -> LabelDocument:
    return LabelDocument(recognized(phones, **kw), duration=1.0, frame_rate=RATE,
                         phone_set=["sil", "ay", "m", "n", "g", "l", "b", "t", "dh", "ah"])


def labels_of(d: LabelDocument) -> list[str]:
    return [s.label for s in d.phones]


def test_rename_a_phone_and_undo_redo_it():
    d = doc()
    d.select(PHONES, 2)
    edit = d.rename("M")                    # any case: the model's phone /m/
    assert labels_of(d) == ["sil", "ay", "m", "g", "l"]
    assert edit.description == "rename /n/ → /m/ at 0.500 s"
    assert d.undo_text == edit.description and d.dirty
    d.undo()
    assert labels_of(d) == ["sil", "ay", "n", "g", "l"] and not d.dirty
    assert d.redo_text == edit.description
    d.redo()
    assert labels_of(d) == ["sil", "ay", "m", "g", "l"] and d.selection == Selection(PHONES, 2)


@pytest.mark.parametrize("typed, why", [
    ("q", "'q' is not a phone of the model"),
    ("zh", "/zh/ is an ARPAbet phone the model was not trained on"),
    ("  ", "type a phone"),
    ("n", "the phone is /n/ already"),
])
def test_a_phone_the_model_does_not_know_is_refused_and_nothing_changes(typed, why):
    d = doc()
    d.select(PHONES, 2)
    with pytest.raises(EditRefused, match=why) as refused:
        d.rename(typed)
    assert "\n" not in str(refused.value)          # one line
    assert labels_of(d) == ["sil", "ay", "n", "g", "l"] and not d.dirty and d.undo_text == ""


def test_a_boundary_snaps_to_frames_and_cannot_cross_its_neighbours():
    d = doc()
    edit = d.move_boundary(2, 0.53)         # /ay/|/n/ from 0.5: 0.53 s is frame 32 (0.5333 s)
    assert d.phones[1].end == d.phones[2].start == pytest.approx(32 / 60)
    assert "move the boundary /ay/|/n/ 0.500 → 0.533 s" == edit.description
    d.move_boundary(2, 0.9)                 # past /n/'s end (0.6): held at the last frame before
    assert d.phones[2].start == pytest.approx(35 / 60) and d.phones[2].end == 0.6
    d.move_boundary(2, 0.0)                 # past /ay/'s start (0.2): the first frame after it
    assert d.phones[2].start == pytest.approx(13 / 60)
    with pytest.raises(EditRefused, match="the first phone starts at 0 s"):
        d.move_boundary(0, 0.1)
    assert d.done == 3
    # a phone shorter than two frames leaves no frame to move to
    short = doc([(0.0, 0.2, "sil"), (0.2, 0.205, "b"), (0.205, 0.215, "ah"), (0.215, 1.0, "l")])
    with pytest.raises(EditRefused, match="no frame between 0.200 and 0.215 s"):
        short.move_boundary(2, 0.21)


def test_split_at_the_cursor_merge_and_delete():
    d = doc()
    d.select(PHONES, 4)                     # /l/ 0.7-1.0
    d.split(0.86)                           # frame 52 = 0.8667 s
    assert [(round(s.start, 4), round(s.end, 4), s.label) for s in d.phones[4:]] == \
        [(0.7, 0.8667, "l"), (0.8667, 1.0, "l")]
    assert d.selection == Selection(PHONES, 5)
    d.rename("ah")
    d.select(PHONES, 4)
    d.split(0.7)                            # at its start (frame 42): the first frame inside
    assert d.phones[4].end == pytest.approx(43 / 60)
    d.select(PHONES, 4)
    d.merge_next()
    assert labels_of(d) == ["sil", "ay", "n", "g", "l", "ah"]
    assert d.phones[4].end == pytest.approx(52 / 60)
    d.select(PHONES, 2)                     # delete /n/: /ay/ before it takes its time
    edit = d.delete()
    assert labels_of(d) == ["sil", "ay", "g", "l", "ah"] and d.phones[1].end == 0.6
    assert edit.description == "delete /n/ at 0.500 s (/ay/ takes its time)"
    d.select(PHONES, 0)                     # the first: the next takes its time
    d.delete()
    assert d.phones[0].start == 0.0 and d.phones[0].label == "ay"
    d.select(PHONES, 1)
    d.mark_silence()
    assert labels_of(d) == ["ay", "sil", "l", "ah"]
    while d.done:
        d.undo()
    assert labels_of(d) == ["sil", "ay", "n", "g", "l"] and not d.dirty
    short = doc([(0.0, 0.2, "sil"), (0.2, 0.21, "b"), (0.21, 1.0, "l")])
    short.select(PHONES, 1)
    with pytest.raises(EditRefused, match=r"split /b/: no frame between 0\.200 and 0\.210 s"):
        short.split(0.205)


def test_words_edges_carry_the_phone_boundaries_on_them():
    words = [(0.2, 0.6, "I'm"), (0.6, 1.0, "glad")]
    d = doc(words=words)
    d.move_word_edge(1, "start", 0.55)      # the shared edge: both words and /n/|/g/ move
    assert (d.words[0].end, d.words[1].start) == (pytest.approx(33 / 60),) * 2
    assert d.phones[2].end == d.phones[3].start == pytest.approx(33 / 60)
    with pytest.raises(EditRefused, match="would vanish"):
        d.move_word_edge(1, "start", 0.3)   # the phone boundary cannot pass /n/'s start (0.5)
    d.select(WORDS, 0)
    d.rename("I am")
    assert d.words[0].label == "I am" and labels_of(d) == ["sil", "ay", "n", "g", "l"]
    d.merge_next()
    assert [w.label for w in d.words] == ["I am glad"]
    d.delete()
    assert d.words == () and len(d.phones) == 5
    d.add_word(0.2, 0.5, "I'm")
    assert [(w.start, w.end, w.label) for w in d.words] == [(pytest.approx(0.2), 0.5, "I'm")]
    with pytest.raises(EditRefused, match="overlaps a word"):
        d.add_word(0.4, 0.7, "glad")
    # moving a phone boundary that is a word's edge moves the word's edge too
    d.move_boundary(2, 0.52)                # /ay/|/n/, 0.5 → frame 31
    assert d.words[0].end == d.phones[2].start == pytest.approx(31 / 60)


def test_changed_phones_count_as_checked_by_hand_as_a_saved_file_reads_back(tmp_path):
    d = doc(conf=[0.9, 0.8, 0.16, 0.7, 0.6])
    d.select(PHONES, 2)
    d.rename("m")
    d.move_boundary(4, 0.75)                # /g/|/l/: both phones change
    now = d.labels_now()
    assert now.hand_checked.tolist() == [False, False, True, True, True]
    assert now.provenance.kind == "recognized" and now.provenance.corrected == 3
    assert now.confidence.round(3).tolist() == [0.9, 0.8, 1.0, 1.0, 1.0]
    path = tmp_path / "im_glad.TextGrid"
    write_labels(path, now, 1.0)
    back = read_label_file(path, 16000, 1.0)
    assert [s.label for s in back.phones] == ["sil", "ay", "m", "g", "l"]
    assert back.hand_checked.tolist() == [False, False, True, True, True]
    assert back.provenance.describe() == "recognized (PocketSphinx 5.1.1), 3 phones corrected by hand"
    assert back.confidence.round(3).tolist() == [0.9, 0.8, 1.0, 1.0, 1.0]
    # opened again and corrected further, the earlier corrections stay checked
    again = LabelDocument(back, 1.0, RATE, ["sil", "ay", "m", "n", "g", "l"])
    again.select(PHONES, 0)
    again.rename("ay")
    assert again.labels_now().hand_checked.tolist() == [True, False, True, True, True]
    # undone, a phone matches its record again: no longer checked
    d.undo()
    assert d.labels_now().hand_checked.tolist() == [False, False, True, False, False]


def test_hand_checked_labels_stay_hand_checked():
    d = LabelDocument(Labels([S(*p) for p in IM_GLAD]), 1.0, RATE)
    d.select(PHONES, 2)
    d.rename("m")
    now = d.labels_now()
    assert now.provenance.hand_checked and now.trust() is None and now.hand_checked.all()


def test_a_new_edit_after_undo_drops_the_redo_and_the_saved_state():
    d = doc()
    d.select(PHONES, 2)
    d.rename("m")
    d.mark_saved()
    assert not d.dirty
    d.undo()
    assert d.dirty
    d.rename("b")                              # the saved state (/m/) can no longer be reached
    assert d.redo_text == "" and d.dirty
    d.undo()
    assert d.dirty                             # the first state is not what was saved
