"""The study report: one self-contained HTML file from a run folder (``report.html``).

* :func:`render_report`: a section per stage, our tables and figures beside what the
  thesis reports in Tables 4.1–4.7 and Figures 4.1–4.19, the honest metrics next to
  the thesis' ones, and a verdict on each of its three hypotheses;
* :data:`THESIS_ITEMS`, :data:`HYPOTHESES`: what the thesis reports, typed in from its text.

This stage reads only the files a run wrote; it imports no other stage.
"""

from joulepath.report._html import Verdict, render_report, verdicts
from joulepath.report._thesis import (
    HYPOTHESES,
    STAGES,
    THESIS_ITEMS,
    Hypothesis,
    ThesisItem,
    items_for_stage,
    thesis_item,
)

__all__ = [
    "HYPOTHESES",
    "Hypothesis",
    "STAGES",
    "THESIS_ITEMS",
    "ThesisItem",
    "Verdict",
    "items_for_stage",
    "render_report",
    "thesis_item",
    "verdicts",
]
