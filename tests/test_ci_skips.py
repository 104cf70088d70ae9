"""In CI (``RSSTP_FAIL_ON_SKIP=1``, set by .ci/run) a skipped test fails the run, naming it."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

CONFTEST = (Path(__file__).parent / "conftest.py").read_text()
SCENARIOS = (Path(__file__).parent / "scenarios.py").read_text()  # what the conftest imports


@pytest.mark.parametrize(("in_ci", "code"), [("1", 1), (None, 0)])
def test_a_skip_fails_ci_and_only_ci(
    pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch, in_ci: str | None, code: int
) -> None:
    if in_ci is None:
        monkeypatch.delenv("RSSTP_FAIL_ON_SKIP", raising=False)
    else:
        monkeypatch.setenv("RSSTP_FAIL_ON_SKIP", in_ci)
    pytester.makeconftest(CONFTEST)
    pytester.makepyfile(scenarios=SCENARIOS)
    pytester.makepyfile(
        test_one="import pytest\n\ndef test_gone():\n    pytest.skip('no tool here')\n"
    )
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider")
    assert result.ret == code
    named = "skipped in CI (not allowed): test_one.py::test_gone" in result.stdout.str()
    assert named == (code == 1)
