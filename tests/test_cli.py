"""The ``odpipe`` command: every help text, the exit statuses, one-line errors, -v/-q/--debug."""

import logging
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

import odpipe.commands
from odpipe.cli import build_parser, main
from odpipe.errors import MEANING, Exit

ROOT = Path(__file__).resolve().parents[1]
COMMANDS = sorted(i.name for i in pkgutil.iter_modules(odpipe.commands.__path__) if not i.name.startswith("_"))


def odpipe_cli(*args):
    """``odpipe ARGS`` in a fresh interpreter, as a user runs it."""
    return subprocess.run([sys.executable, "-m", "odpipe.cli", *args], capture_output=True, text=True, cwd=ROOT)


def test_every_command_module_registers():
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    assert sorted(sub.choices) == COMMANDS


def test_cli_runs_as_module():
    out = odpipe_cli("--version")
    assert out.returncode == 0 and out.stdout.startswith("odpipe ")


@pytest.mark.parametrize("args", [["--help"], []], ids=["--help", "bare"])
def test_top_level_help_lists_commands_and_exit_statuses(args):
    out = odpipe_cli(*args)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("usage: odpipe") and out.stderr == ""
    for name in COMMANDS:
        assert re.search(rf"^\s+{name}\s", out.stdout, re.M), name
    table = out.stdout.split("exit status:\n", 1)[1]
    rows = dict(re.findall(r"^\s+(\d+)\s+(.+)$", table, re.M))
    assert {int(k): v for k, v in rows.items()} == {int(k): v for k, v in MEANING.items()}


def test_the_readmes_exit_table_is_the_commands():
    text = (ROOT / "README.md").read_text()
    rows = dict(re.findall(r"^\| (\d+) \| (.+) \|$", text.split("| exit | meaning |", 1)[1].split("\n\n", 1)[0], re.M))
    assert {int(k): v.replace("`", "") for k, v in rows.items()} == {int(k): v for k, v in MEANING.items()}


@pytest.mark.parametrize("name", COMMANDS)
def test_every_command_help(name, capsys):
    with pytest.raises(SystemExit) as done:
        main([name, "--help"])
    assert done.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"usage: odpipe {name}") and "--debug" in out and "--quiet" in out


def test_usage_error_is_status_2(capsys):
    with pytest.raises(SystemExit) as done:
        main(["run"])
    assert done.value.code == Exit.INPUT == 2
    assert "the following arguments are required: config" in capsys.readouterr().err


def _stderr_lines(capsys):
    return capsys.readouterr().err.splitlines()


def test_missing_and_folder_inputs_are_one_line(tmp_path, capsys):
    assert main(["run", str(tmp_path / "absent.toml")]) == 2
    assert _stderr_lines(capsys) == [f"error: {tmp_path / 'absent.toml'}: No such file or directory"]
    assert main(["batch", str(tmp_path)]) == 2
    assert _stderr_lines(capsys) == [f"error: {tmp_path}: Is a directory"]


def test_parse_error_names_the_file_and_byte(tmp_path, capsys):
    """A TRK-2-34 file cut inside its 11th record: the reader's ParseError, one line, status 2."""
    cut = tmp_path / "cut.tnf"
    cut.write_bytes((ROOT / "fixtures/trk234/sample.tnf").read_bytes()[:3000])
    assert main(["convert", str(cut), "-o", str(tmp_path / "x.parquet")]) == 2
    (line,) = _stderr_lines(capsys)
    assert re.fullmatch(rf"error: {re.escape(str(cut))}, byte \d+, record 11: .*end of the file", line), line


def test_bad_values_of_commands_are_one_line(tmp_path, capsys):
    assert main(["overlap", str(tmp_path / "a.oem")]) == 2
    assert _stderr_lines(capsys) == ["error: odpipe overlap needs at least two OEM files, got 1"]
    assert main(["maneuvers", str(tmp_path)]) == 2
    assert _stderr_lines(capsys) == [f"error: {tmp_path}: no maneuvers.csv (did the run estimate maneuvers?)"]
    (tmp_path / "maneuvers.csv").write_text("a,b\n1,2\n")
    assert main(["maneuvers", str(tmp_path)]) == 2
    assert _stderr_lines(capsys)[0].startswith(f"error: {tmp_path / 'maneuvers.csv'}: not a maneuvers.csv of a run")


@pytest.fixture
def fake_run(monkeypatch):
    """``odpipe run`` with run_config replaced by ``behaviour(progress)``."""
    import odpipe.pipeline.run

    def install(behaviour):
        monkeypatch.setattr(odpipe.pipeline.run, "run_config",
                            lambda path, force=False, progress=None: behaviour(progress))
    return install


def test_fit_failure_is_status_3_naming_the_config(fake_run, capsys):
    from odpipe.estimation.fit import FitDiverged

    def diverge(progress):
        raise FitDiverged("not converged in 10 iterations; post-fit RMS 412 sigma (best iteration 3.1)")
    fake_run(diverge)
    assert main(["run", "arc.toml"]) == Exit.FIT == 3
    assert _stderr_lines(capsys) == ["error: fit failed: arc.toml: not converged in 10 iterations; "
                                     "post-fit RMS 412 sigma (best iteration 3.1)"]


def test_a_bug_is_status_1_and_debug_shows_the_traceback(fake_run, capsys):
    def bug(progress):
        return {}["status"]
    fake_run(bug)
    assert main(["run", "arc.toml"]) == Exit.INTERNAL == 1
    (line,) = _stderr_lines(capsys)
    assert line == "error: internal error (KeyError: 'status'); this is a bug: rerun with --debug for the traceback"
    assert main(["--debug", "run", "arc.toml"]) == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and 'return {}["status"]' in err


def test_interrupt_is_status_130(fake_run, capsys):
    def interrupt(progress):
        raise KeyboardInterrupt
    fake_run(interrupt)
    assert main(["run", "arc.toml"]) == Exit.INTERRUPTED == 130
    assert _stderr_lines(capsys) == ["error: interrupted"]


def test_progress_goes_to_stderr_and_verbosity_flags(fake_run, tmp_path, capsys):
    def arc(progress):
        progress("fit: converged in 3 iterations")
        logging.getLogger("odpipe.pipeline.run").debug("a detail")
        return {"status": "complete", "run": str(tmp_path / "current")}
    fake_run(arc)
    assert main(["run", "arc.toml"]) == 0
    out = capsys.readouterr()
    assert out.out == f"complete: {tmp_path / 'current' / 'report.html'}\n"  # the product, alone on stdout
    assert out.err == "fit: converged in 3 iterations\n"
    for args in (["-q", "run", "arc.toml"], ["run", "arc.toml", "-q"]):  # before or after the command
        assert main(args) == 0
        assert capsys.readouterr().err == ""
    assert main(["run", "arc.toml", "-v"]) == 0
    assert capsys.readouterr().err.splitlines() == ["fit: converged in 3 iterations",
                                                    "debug: odpipe.pipeline.run: a detail"]


def test_fit_iterations_are_logged_as_they_run(caplog):
    """Long fits show progress: each iteration's RMS and edits, logged by the fit as it goes."""
    import numpy as np
    from odpipe.estimation.fit import FitOptions, fit
    from estimation_cases import twobody_case

    prob, obs, _ = twobody_case(np.random.default_rng(3))
    with caplog.at_level(logging.INFO, logger="odpipe.estimation.fit"):
        sol = fit(prob, obs, 0.0, 86400.0, FitOptions(block=600.0))
    lines = [r.getMessage() for r in caplog.records if r.name == "odpipe.estimation.fit"]
    assert len(lines) == len(sol.history) >= 2
    for k, (line, h) in enumerate(zip(lines, sol.history), start=1):
        assert line.startswith(f"fit iteration {k}: post-fit RMS {h['postfit_rms']:.4g} sigma "
                               f"(pre-fit {h['prefit_rms']:.4g}), {h['edited']} rows edited"), line


def test_other_libraries_progress_stays_quiet(fake_run, capsys):
    """Dask's INFO chatter (its loggers propagate at INFO) is not shown; its warnings are."""
    def arc(progress):
        logging.getLogger("distributed.scheduler").info("Receive client connection")
        logging.getLogger("distributed.worker").warning("Worker is at 85% memory usage")
        return {"status": "skipped", "run": "out/a/current"}
    fake_run(arc)
    dask, before = logging.getLogger("distributed"), logging.getLogger("distributed").level
    dask.setLevel(logging.INFO)  # as Dask configures it
    try:
        assert main(["run", "arc.toml"]) == 0
    finally:
        dask.setLevel(before)
    assert capsys.readouterr().err == "warning: Worker is at 85% memory usage\n"


def test_apriori_refuses_a_run_that_is_not_about_the_moon(tmp_path, capsys):
    """`odpipe apriori` on the peers' Earth-orbit case: one line naming the config and its centre, status 2."""
    from heo_case import write_config

    import pandas as pd

    write_config(tmp_path, "heo", "2003-06-03T00:00:00", "2003-06-03T06:00:00", [7e6, 0, 0, 0, 7.5e3, 0], "")
    pd.DataFrame({"epoch": []}).to_parquet(tmp_path / "tracking.parquet")  # never read: the centre is refused first
    assert main(["apriori", str(tmp_path / "arc.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "arc.toml" in err and "dynamics.center" in err and "lunar orbiter" in err


def test_simulate_case_errors_name_the_file_and_key(tmp_path, capsys):
    text = (ROOT / "runs" / "artemis_p2_like.toml").read_text()
    (tmp_path / "noseed.toml").write_text("\n".join(ln for ln in text.splitlines() if not ln.startswith("seed")))
    assert main(["simulate", str(tmp_path / "noseed.toml"), "-o", str(tmp_path / "out")]) == 2
    assert _stderr_lines(capsys) == [f"error: {tmp_path / 'noseed.toml'}: [seed] required key is missing"]
    bad = text.replace("\npass_s = 2700.0", "\npass_sec = 2700.0")         # the third [[network]], BGS
    line = bad.splitlines().index("pass_sec = 2700.0") + 1
    (tmp_path / "pass.toml").write_text(bad)
    assert main(["simulate", str(tmp_path / "pass.toml"), "-o", str(tmp_path / "out")]) == 2
    (err,) = _stderr_lines(capsys)
    assert err.startswith(f"error: {tmp_path / 'pass.toml'}:{line}: [network[2].pass_sec] unknown key (allowed: ")
    assert not (tmp_path / "out").exists()
