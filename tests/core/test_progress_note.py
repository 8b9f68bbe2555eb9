"""The planner's progress note: written whole where $TMM_PROGRESS_FILE says, nothing without it, read back or None."""
from __future__ import annotations

from tmm_workbench.core.plan import progress_note


def test_a_note_written_whole_and_read_back(tmp_path, monkeypatch):
    path = tmp_path / "progress.json"
    monkeypatch.setenv(progress_note.ENV, str(path))
    progress_note.note(1, 0, "analysing the model and planning")
    first = progress_note.read(path)
    assert progress_note.words(first) == "analysing the model and planning"
    progress_note.note(3, 6, "computing TMM Waterline")
    assert progress_note.words(progress_note.read(path)) == "computing TMM Waterline (step 3 of 6)"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["progress.json"]   # no half-written part left


def test_no_variable_no_file_and_bad_files_read_as_none(tmp_path, monkeypatch):
    monkeypatch.delenv(progress_note.ENV, raising=False)
    progress_note.note(1, 2, "x")
    assert not list(tmp_path.iterdir())
    assert progress_note.read(tmp_path / "missing.json") is None
    (tmp_path / "half.json").write_text('{"step": 1, "ste')
    (tmp_path / "other.json").write_text('{"step": 1}')
    assert progress_note.read(tmp_path / "half.json") is None and progress_note.read(tmp_path / "other.json") is None


def test_a_folder_gone_never_fails_the_plan(tmp_path, monkeypatch):
    monkeypatch.setenv(progress_note.ENV, str(tmp_path / "gone" / "progress.json"))
    progress_note.note(2, 5, "computing TMM Surface")   # no error: progress is for people
