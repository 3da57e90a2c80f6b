"""The configuration reference is generated from the schemas (run configurations, simulated cases), covers
every key, and docs/config.md is it."""

import dataclasses
import typing
from pathlib import Path

import pytest

from odpipe.cli import main
from odpipe.commands.reference import document
from odpipe.pipeline.config import RunConfig, reference
from odpipe.operations.reference import field_comments, sections
from odpipe.simulate.case import CaseFile

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("schema", [RunConfig, CaseFile])
def test_every_key_has_a_description(schema):
    missing = [f"{key}.{f.name}" if key else f.name
               for key, cls in sections(schema) for f in dataclasses.fields(cls)
               if not f.metadata.get("internal") and not field_comments(cls).get(f.name)
               and not (key == "" and dataclasses.is_dataclass(typing.get_type_hints(cls)[f.name]))]
    assert missing == []


def test_docs_config_md_is_the_generated_reference():
    from odpipe.commands.reference import document

    assert document().startswith(reference())
    assert (ROOT / "docs" / "config.md").read_text() == document(), "run: odpipe reference -o docs/config.md"


def test_reference_command_prints_every_section(capsys):
    assert main(["reference"]) == 0
    out = capsys.readouterr().out
    for key in ("[run]", "[arc]", "[data]", "[dynamics.gravity]", "[initial_state.from_doppler]",
                "[estimation.stochastic]", "[products]"):
        assert f"## `{key}`" in out
    assert "| `elevation_mask_deg` | number | `10.0` | deg, at the receiving station |" in out
    assert "# Simulated case reference" in out
    for key in ("[orbit]", "[spacecraft_model]", "[station_keeping]", "[network]", "[maneuver]"):
        assert f"## `{key}`" in out
    assert "| `range_bias_sigma` | number | `0.0` | m, range bias, one draw per pass |" in out
