"""The thesis' reported results (joulepath.report._thesis) against the thesis text itself."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from joulepath.errors import InvalidInput
from joulepath.report._thesis import (
    HYPOTHESES,
    STAGES,
    THESIS_ITEMS,
    ThesisItem,
    items_for_stage,
    thesis_item,
)

SEED = Path(__file__).resolve().parents[2].parent / "shared" / "seed" / "000_c43d5ab320f1a219.txt"
WINDOW = 80
"""A number must be printed within this many lines of its item's caption."""

EXPECTED_KEYS = (
    [f"Figure 4.{i}" for i in range(1, 11)]
    + [f"Table 4.{i}" for i in range(1, 5)]
    + [f"Figure 4.{i}" for i in range(11, 19)]
    + ["Table 4.5", "Table 4.6", "Figure 4.19", "Table 4.7"]
)
"""All 26 tables and figures of Chapter 4, in the order their captions appear."""

GARBLED = {"Table 4.7"}
"""Items whose table cells lost their decimal points in the PDF-to-text conversion ("72 71")."""

NUMBER = re.compile(r"\d+(?:[.,]\d+)*")

if not SEED.is_file():
    pytest.skip(f"thesis text not found at {SEED}", allow_module_level=True)

LINES = SEED.read_text(encoding="utf-8").splitlines()
TEXT = "\n".join(LINES)


def _printed(token: str, text: str, *, lost_point: bool = False) -> bool:
    """True when ``token`` (e.g. "51.96") occurs in ``text`` as a whole number, not inside a longer one."""
    body = re.escape(token)
    if lost_point:
        body = body.replace(r"\.", r"[.\s]")
    return re.search(rf"(?<![\d.,]){body}(?!\d)", text) is not None


def _window(line: int) -> str:
    return "\n".join(LINES[max(line - 1 - WINDOW, 0) : line + WINDOW])


# ---- structure ------------------------------------------------------------------------------


def test_thesis_items_keys_are_all_tables_and_figures_of_chapter_4_in_thesis_order():
    keys = [item.key for item in THESIS_ITEMS]
    assert keys == EXPECTED_KEYS
    assert len(set(keys)) == len(keys) == 26


def test_thesis_items_lines_increase_in_thesis_order():
    lines = [item.line for item in THESIS_ITEMS]
    assert lines == sorted(lines)
    assert len(set(lines)) == len(lines)


def test_thesis_items_fields_are_filled_and_numbers_short():
    for item in THESIS_ITEMS:
        assert item.caption and item.shows and item.section.startswith("4."), item.key
        assert "$" not in item.caption and "**" not in item.caption, item.key
        assert len(item.numbers) <= 10, item.key
        labels = [label for label, _ in item.numbers]
        assert len(set(labels)) == len(labels), f"{item.key}: duplicate labels"
        for label, value in item.numbers:
            assert label.strip() and NUMBER.search(value), (item.key, label, value)


def test_thesis_item_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        thesis_item("Table 4.1").stage = "bench"  # type: ignore[misc]


def test_thesis_item_rejects_unknown_stage():
    with pytest.raises(InvalidInput, match="stage 'nope'"):
        ThesisItem("Table 9.9", "c", "9.9", "nope", "s", (), 1)


# ---- lookups --------------------------------------------------------------------------------


def test_thesis_item_returns_the_item_with_that_key():
    for item in THESIS_ITEMS:
        assert thesis_item(item.key) is item


def test_thesis_item_unknown_key_names_the_valid_keys():
    with pytest.raises(InvalidInput, match="Table 4.8") as info:
        thesis_item("Table 4.8")
    message = str(info.value)
    for key in EXPECTED_KEYS:
        assert key in message


def test_items_for_stage_partitions_the_items():
    assert all(item.stage in STAGES for item in THESIS_ITEMS)
    collected = [item for stage in STAGES for item in items_for_stage(stage)]
    assert sorted(collected, key=lambda item: item.line) == list(THESIS_ITEMS)
    for stage in STAGES:
        assert all(item.stage == stage for item in items_for_stage(stage))


def test_items_for_stage_follows_the_pipeline_mapping():
    def keys(stage: str) -> list[str]:
        return [item.key for item in items_for_stage(stage)]

    assert keys("importance") == ["Figure 4.1", "Figure 4.2"]
    assert keys("synth") == [f"Figure 4.{i}" for i in range(3, 11)]
    assert keys("train") == [f"Table 4.{i}" for i in range(1, 5)] + [f"Figure 4.{i}" for i in range(11, 19)]
    assert keys("bench") == ["Table 4.5", "Table 4.6", "Figure 4.19"]
    assert keys("optimize") == ["Table 4.7"]
    assert keys("data") == []


def test_items_for_stage_unknown_stage_raises():
    with pytest.raises(InvalidInput, match="expected one of: data, synth"):
        items_for_stage("training")


# ---- against the thesis text ------------------------------------------------------------------


@pytest.mark.parametrize("item", THESIS_ITEMS, ids=lambda item: item.key)
def test_thesis_item_line_holds_its_caption(item):
    line = LINES[item.line - 1]
    # "Figure 4.1:" or "**Table 4.1:**"; "Figure 4.1" must not match "Figure 4.10".
    assert re.search(rf"{re.escape(item.key)}(?!\d)\W*:", line), line
    assert item.caption[:20] in line


@pytest.mark.parametrize("item", THESIS_ITEMS, ids=lambda item: item.key)
def test_thesis_item_section_is_the_heading_above_its_caption(item):
    heading = re.compile(r"^#+\s*\**\s*(4(?:\.\d+)+)\b")
    sections = [m.group(1) for text in LINES[: item.line] if (m := heading.match(text.strip()))]
    assert sections and sections[-1] == item.section


@pytest.mark.parametrize("item", THESIS_ITEMS, ids=lambda item: item.key)
def test_thesis_item_numbers_are_printed_near_the_caption(item):
    window = _window(item.line)
    for label, value in item.numbers:
        for token in NUMBER.findall(value):
            assert _printed(token, window, lost_point=item.key in GARBLED), (label, value, token)


@pytest.mark.parametrize("item", THESIS_ITEMS, ids=lambda item: item.key)
def test_thesis_item_labels_and_prose_invent_no_number(item):
    for text in (item.shows, item.caption, *(label for label, _ in item.numbers)):
        for token in NUMBER.findall(text):
            assert _printed(token, TEXT, lost_point=item.key in GARBLED), (text, token)


def test_printed_rejects_a_number_inside_a_longer_one():
    assert _printed("0.99", "R2 of 0.99, MAE")
    assert not _printed("0.99", "R2 of 0.999")
    assert not _printed("0.2", "MAE 0.25")
    assert not _printed("72.71", "72 71")
    assert _printed("72.71", "72 71", lost_point=True)


def test_hypotheses_are_verbatim_on_their_lines():
    assert [h.key for h in HYPOTHESES] == ["H1", "H2", "H3"]
    for hypothesis in HYPOTHESES:
        line = LINES[hypothesis.line - 1]
        assert hypothesis.text[:30] in line
        assert hypothesis.text in line  # the whole hypothesis is one line of the text
