"""``odpipe batch``: an arc whose configuration is wrong, absent or starts from a failed arc fails alone
(summary, night report, exit status 4); the rest run; arc globs may be absolute."""

import html
import re
from pathlib import Path

from odpipe.cli import main
from odpipe.pipeline import setup as build
from odpipe.pipeline.config import load_config
from odpipe.operations import rundir

TRACKING = Path(__file__).resolve().parents[1] / "fixtures" / "trk234" / "sample.tnf"


def arc_text(name: str, start: str = "2020-01-01T00:00:00", initial: str = "state = [7.0e6, 0, 0, 0, 7.5e3, 0]"):
    return f"""[run]
name = "{name}"
output = "../out"
[arc]
spacecraft = "1"
start = "{start}"
end = "2020-01-02T00:00:00"
[data]
files = ["{TRACKING}"]
[dynamics]
center = "earth"
[initial_state]
epoch = "2020-01-01T00:00:00"
{initial}
"""


def _done_before(path: Path) -> None:
    """Give the arc of ``path`` a complete run with its current config and inputs (so the batch skips it)."""
    cfg = load_config(path)
    attempt = rundir.start(cfg.run.output / cfg.run.name)
    attempt.finish(rundir.fingerprint(cfg.text, build.input_files(cfg)))


def test_bad_arcs_fail_alone_and_the_rest_run(tmp_path, capsys):
    arcs = tmp_path / "arcs"
    arcs.mkdir()
    (arcs / "good.toml").write_text(arc_text("good"))
    _done_before(arcs / "good.toml")
    bad = arc_text("bad", start="2020-02-30T00:00:00").replace('center = "earth"', 'center = "earth"\nmas = 1.0')
    (arcs / "bad.toml").write_text(bad)
    (arcs / "chained.toml").write_text(arc_text(
        "chained", initial='from_oem = "../out/bad/current/trajectory.oem"'))  # starts from the bad arc
    night = tmp_path / "nightly.toml"
    night.write_text(f'[batch]\narcs = ["{arcs}/*.toml", "absent.toml"]\nworkers = 1\nreport = "night"\n')

    assert main(["batch", str(night)]) == 4
    out = capsys.readouterr()
    lines = out.out.splitlines()
    assert lines[0] == "4 arcs: 0 run, 1 unchanged (skipped), 3 failed"
    failed = dict(re.match(r"  FAILED (\S+): (.*)", ln).groups() for ln in lines[1:4])
    line = lambda needle: next(i for i, ln in enumerate(bad.splitlines(), 1) if needle in ln)  # noqa: E731
    assert failed == {
        str(tmp_path / "absent.toml"): f"{tmp_path / 'absent.toml'}: No such file or directory",
        str(arcs / "bad.toml"): (f"{arcs / 'bad.toml'}: 2 problems: line {line('start =')} [arc.start] "
                                 "'2020-02-30T00:00:00' is not a valid time: day out of range; "
                                 f"line {line('mas =')} [dynamics.mas] unknown key (allowed: center, drag, "
                                 "ephemeris, gravity, mass, polynomial_acceleration, relativity, srp, third_bodies)"),
        str(arcs / "chained.toml"): "not run: it starts from bad.toml, which failed",
    }
    assert lines[4] == f"report: {tmp_path / 'night' / 'report.html'}"
    assert "good.toml: skipped" in out.err and "chained.toml: failed" in out.err  # progress on stderr
    page = (tmp_path / "night" / "report.html").read_text()
    assert "<title>odpipe batch nightly</title>" in page   # named by its configuration, nightly.toml
    assert f"<td>{night}</td>" in page
    cells = [html.unescape(c) for c in re.findall(r"<td[^>]*>([^<]*)</td>", page)]
    assert "Failed arcs" in page and cells.count("bad.toml") == 1 and cells.count("absent.toml") == 1
    assert failed[str(arcs / "bad.toml")] in cells  # the whole message, as in the summary
    assert not (tmp_path / "out" / "chained").exists()


def test_batch_config_problems_are_one_line(tmp_path, capsys):
    night = tmp_path / "nightly.toml"
    night.write_text('[batch]\narcs = ["arcs/*.toml"]\nworker = 2\n')
    assert main(["batch", str(night)]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"error: {night}: 2 problems: line 2 [batch.arcs[0]] no file matches 'arcs/*.toml'; "
        "line 3 [batch.worker] unknown key (allowed: arcs, overlaps, report, workers)"]
    night.write_text('[batch]\narcs = []\nworkers = 0\n')
    assert main(["batch", str(night)]) == 2
    assert capsys.readouterr().err.splitlines() == [f"error: {night}:3: [batch.workers] 0 must be positive and finite"]
