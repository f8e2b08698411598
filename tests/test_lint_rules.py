"""The house of ``check`` (issue 29 item 10): a table of small rules, one module per family, ``--list-rules``.

What is checked: the table (:data:`scara_pin.lint.RULES`) names each code once, each rule's function lives in
its family's module and is small; every code ``check`` reports on the fixtures of tests/data (and on files
broken here on purpose) is a registered rule; ``check --list-rules`` prints the table, a line per rule.
"""

from __future__ import annotations

import inspect
import json
from pathlib import Path

import pytest

from scara_pin import generate_urdf
from scara_pin.cli import main
from scara_pin.lint import FAMILIES, RULES, Severity, check_urdf, check_urdf_file

DATA = Path(__file__).parent / "data"
RULE_LINES = 40
"""The longest rule function (lines of source, docstring included): a rule is a small function."""


def test_table_names_each_code_once_in_its_family_module() -> None:
    codes = [r.code for r in RULES]
    assert len(codes) == len(set(codes)), [c for c in codes if codes.count(c) > 1]
    for rule in RULES:
        assert rule.family in FAMILIES
        assert rule.check.__module__ == f"scara_pin.lint.{rule.family}", (rule.code, rule.check.__module__)
        lines = len(inspect.getsourcelines(rule.check)[0])
        assert lines <= RULE_LINES, (rule.code, lines)
        assert rule.check.__doc__, rule.code
        assert rule.summary and "\n" not in rule.summary
    assert not (Path(inspect.getfile(check_urdf)).parent.parent / "lint.py").exists()


def test_every_code_reported_is_a_registered_rule(tmp_path: Path) -> None:
    """The fixtures of every earlier round, and texts broken on purpose: no finding outside the table."""
    registered = {r.code: r for r in RULES}
    seen: set[str] = set()
    reports = [check_urdf_file(p) for p in sorted(DATA.rglob("*.urdf"))]
    text = generate_urdf("default")
    broken = [text.replace("<robot ", "<robo ").replace("</robot>", "</robo>"), text[: len(text) // 2],
              text.replace('type="revolute"', 'type="hinge"', 1), text.replace('velocity="', 'velocity="1e9', 1)]
    reports += [check_urdf(t) for t in broken]
    reports.append(check_urdf_file(tmp_path / "missing.urdf"))
    for report in reports:
        for f in report.findings:
            assert f.code in registered, f.code
            rule = registered[f.code]
            order = [Severity.INFO, Severity.WARNING, Severity.ERROR]
            assert order.index(f.severity) <= order.index(rule.severity), (f.code, f.severity)
            seen.add(f.code)
    assert {"unreadable", "malformed-xml", "root-not-robot", "joint-type", "joints", "geared"} <= seen


def test_list_rules_prints_the_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", "--list-rules"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == len(RULES)
    for line, rule in zip(out, RULES):
        code, severity, family, summary = line.split(None, 3)
        assert (code, severity, family, summary) == (rule.code, rule.severity.value, rule.family, rule.summary)
    assert main(["check", "--list-rules", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rules"]
    assert [r["code"] for r in rows] == [r.code for r in RULES]
    assert main(["check", "--list-rules", str(DATA / "default.urdf")]) == 2
    assert main(["check"]) == 2
    err = capsys.readouterr().err
    assert err.count("error:") == 2 and "Traceback" not in err
