"""research/statements: the count of the paper's statements regenerates docs/results.md's table from the records."""
import pathlib
import re

import pytest

from research.statements import count

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def rows():
    return count.rows()


def test_verdict_rule():
    assert count.verdict([True, True]) == "holds"
    assert count.verdict([True, False]) == "holds in part"
    assert count.verdict([True, None]) == "holds in part"
    assert count.verdict([False, None]) == "fails"
    assert count.verdict([None, None]) == "cannot be judged"


def test_every_statement_counted_once(rows):
    assert [r.id for r in rows] == [f"P{k}" for k in range(1, 34)]
    assert all(r.verdict in count.VERDICTS for r in rows)
    assert sum(count.counts(rows).values()) == 33


def test_the_section_is_the_scripts_output(rows):
    section = (ROOT / "docs" / "results.md").read_text().split("## Status against the paper\n", 1)[1]
    section = section.split("\n## ", 1)[0]
    assert count.table(rows).strip() in section
    c = count.counts(rows)
    assert (f"**Count: {c['holds']} hold, {c['holds in part']} hold in part, {c['fails']} fail and "
            f"{c['cannot be judged']} cannot be judged**") in section


def test_readme_states_the_count(rows):
    c = count.counts(rows)
    readme = re.sub(r"\s+", " ", (ROOT / "README.md").read_text())
    assert (f"33 checkable statements, {c['holds']} hold, {c['holds in part']} hold in part, {c['fails']} fail and "
            f"{c['cannot be judged']} cannot be judged") in readme
