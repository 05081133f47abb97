"""The site's reference pages (docs/gen_reference.py) miss nothing the code has.

Each page is generated from the code when the site is built; these tests walk the same code by
other means and check that every command and option, every model-file key and every archive
variable has its entry, with the units the code gives it.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def gen():
    spec = importlib.util.spec_from_file_location("gen_reference", ROOT / "docs" / "gen_reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _section(text: str, heading: str) -> str:
    """The text under *heading* up to the next heading of the same or a higher level."""
    level = heading.split(" ")[0]
    start = text.index(heading + "\n")
    following = re.search(rf"^#{{1,{len(level)}}} ", text[start + len(heading):], re.M)
    return text[start: start + len(heading) + (following.start() if following else len(text))]


def _commands(parser: argparse.ArgumentParser, path: str = "pounding"):
    """(command path, parser) of every command and subcommand, walked through argparse's actions."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield f"{path} {name}", sub
                yield from _commands(sub, f"{path} {name}")


def test_the_cli_reference_has_every_command_and_option(gen):
    from pounding.cli import build_parser

    text = gen.cli_reference()
    commands = list(_commands(build_parser(None)))
    assert any(path.count(" ") == 2 for path, _ in commands), "no nested subcommand (records list) was walked"
    for path, parser in commands:
        section = _section(text, f"## `{path}`")
        for action in parser._actions:
            for option in action.option_strings:
                if option not in ("-h", "--help"):
                    assert f"`{option}`" in section, f"{path}: {option} missing from its section"
            if not action.option_strings and not isinstance(action, argparse._SubParsersAction):
                assert f"`{action.metavar or action.dest}`" in section, f"{path}: argument {action.dest} missing"


def _every_model():
    from pounding.contact.laws import LAWS
    from pounding.contact.links import LINK_LAWS
    from pounding.hysteresis import HYSTERESES
    from pounding.model import plan_schema, schema

    return {schema.TopLevel, plan_schema.PlanModelEntry, *schema.TAGS.values(), *LAWS.values(),
            *LINK_LAWS.values(), *HYSTERESES.values()}


def test_the_yaml_reference_has_every_key_with_its_default(gen):
    from pydantic import BaseModel

    text = gen.yaml_reference()
    models = _every_model()
    # the nested mappings of those models (storeys, damping, foundation, IMK directions...)
    queue = list(models)
    while queue:
        for info in queue.pop().model_fields.values():
            for child in gen._models_in(info.annotation):
                if issubclass(child, BaseModel) and child not in models:
                    models.add(child)
                    queue.append(child)
    for model in models:
        section = _section(text, f"### {model.__name__} {{#{model.__name__.lower()}}}")
        for key, info in model.model_fields.items():
            if key == "parameters" and not info.description:
                continue   # a law's own keys: the law's section
            row = re.search(rf"^\| `{re.escape(key)}` \|.*$", section, re.M)
            assert row, f"{model.__name__}.{key} missing"
            if info.is_required():
                assert "| required |" in row.group(0), f"{model.__name__}.{key} is required"
            elif isinstance(info.default, (int, float)) and not isinstance(info.default, bool):
                assert f"`{info.default}`" in row.group(0), f"{model.__name__}.{key}: default {info.default}"


def test_the_archive_reference_has_every_variable_of_a_run_with_its_units(gen):
    import pounding

    text = gen.archive_reference()
    # a model the generator's list holds, run on its own, longer than the generator runs it
    ds = pounding.simulate(pounding.load_model(ROOT / "models" / "pair_links.yaml"), duration=2.0)
    for name in [*ds.coords, *ds.data_vars]:
        row = re.search(rf"^\| `{re.escape(str(name))}` \| ([^|]*) \| ([^|]*) \|", text, re.M)
        assert row, f"archive variable {name} missing"
        assert row.group(2).strip() == ds[name].attrs.get("units", ""), f"{name}: units"


@pytest.mark.parametrize("target, page, expected", [
    ("docs/gap.md#options", "index.md", "gap.md#options"),             # the README, the site's home page
    ("../models/README.md#walls", "howto/torsion.md", "../models/README.md#walls"),
    ("../docs/ida.md", "models/README.md", "../ida.md"),               # models/README.md, a page of the site
    ("docs/howto/gap.md", "index.md", "howto/gap.md"),
    ("CHANGELOG.md", "index.md", "changelog.md"),
    ("development/performance-log.md", "performance.md", "development/performance-log.md"),
    ("../performance.md#plan-models", "development/performance-log.md", "../performance.md#plan-models"),
    ("https://example.org/x.md", "index.md", "https://example.org/x.md"),
    ("#layout", "architecture.md", "#layout"),
    ("models/pair.yaml", "index.md", None),                            # not a page: shown as its path
    ("../tests/test_opensees.py", "performance.md", None),
])
def test_a_repository_link_becomes_the_site_s(target, page, expected):
    """docs/hooks.py: links written as they work in the repository point at the same page in the site."""
    pytest.importorskip("mkdocs", reason="the site's hooks need mkdocs (the docs extra)")
    spec = importlib.util.spec_from_file_location("hooks", ROOT / "docs" / "hooks.py")
    hooks = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hooks)
    assert hooks.site_link(target, page) == expected
