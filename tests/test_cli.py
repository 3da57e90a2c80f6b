import subprocess
import sys

from odpipe.cli import build_parser


def test_every_command_module_registers():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    import pkgutil, odpipe.commands
    names = {i.name for i in pkgutil.iter_modules(odpipe.commands.__path__) if not i.name.startswith("_")}
    assert len(sub.choices) == len(names)


def test_cli_runs_as_module():
    out = subprocess.run([sys.executable, "-m", "odpipe.cli", "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and "odpipe" in out.stdout
