"""The reference pages of the documentation site, generated from the code so that they cannot drift.

Three Markdown pages, each read from the code itself at build time (``docs/hooks.py`` adds them to
the site; ``python docs/gen_reference.py DIR`` writes them to DIR to look at):

* :func:`cli_reference` -- every ``pounding`` command and option, from the argument parser
  (:func:`pounding.cli.build_parser`): usage, help, choices and defaults;
* :func:`yaml_reference` -- every key of a model file, from the pydantic models that validate it
  (:mod:`pounding.model.schema`, :mod:`pounding.model.plan_schema`, the contact-law, link and
  hysteresis registries): type, default, and the description with its units;
* :func:`archive_reference` -- every variable of a run archive, with its units and long name, from
  short runs of the shipped models (:func:`pounding.simulate`).
"""

from __future__ import annotations

import argparse
import sys
import types
import typing
from pathlib import Path

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

ROOT = Path(__file__).resolve().parents[1]

#: Shipped models whose short runs list the archive variables: together they hold every kind of
#: variable (yielding storeys, links, walls, foundations, several grounds, floors in plan, friction).
ARCHIVE_MODELS = ("pair.yaml", "pair_collapse.yaml", "pair_links.yaml", "pair_bumper.yaml", "pair_column.yaml",
                  "pair_wave_passage.yaml", "pair_on_soil.yaml", "isolated_moat.yaml", "corner_pair.yaml",
                  "isolated_moat_plan.yaml")

#: Simulated time of those runs, s: variables do not depend on it, and 1 s keeps the build short.
ARCHIVE_DURATION = 1.0


def _cell(text: object) -> str:
    """*text* fit for one Markdown table cell."""
    return " ".join(str(text).split()).replace("|", "\\|")


# --------------------------------------------------------------------------- #
# The command line
# --------------------------------------------------------------------------- #


def _subcommands(parser: argparse.ArgumentParser) -> list[tuple[str, str, argparse.ArgumentParser]]:
    """(name, one-line help, parser) of each subcommand of *parser*, in the parser's order."""
    out = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help or "" for a in action._choices_actions}
            out += [(name, helps.get(name, ""), sub) for name, sub in action.choices.items()]
    return out


def _option_row(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    formatter = parser._get_formatter()
    names = ", ".join(f"`{s}`" for s in action.option_strings) or f"`{action.metavar or action.dest}`"
    if action.nargs != 0 and action.option_strings:
        names += f" `{formatter._format_args(action, formatter._get_default_metavar_for_optional(action))}`"
    helptext = formatter._expand_help(action) if action.help else ""
    if action.choices is not None and not isinstance(action, argparse._SubParsersAction):
        helptext += f" (one of: {', '.join(map(str, action.choices))})"
    default = action.default
    shown = "" if default in (None, False, argparse.SUPPRESS) or action.nargs == 0 else f"`{default}`"
    return f"| {names} | {_cell(helptext)} | {_cell(shown)} |"


def _command_section(path: str, helptext: str, parser: argparse.ArgumentParser) -> list[str]:
    lines = [f"## `{path}`", ""]
    if helptext:
        lines += [helptext[:1].upper() + helptext[1:] + ".", ""]
    if parser.description and parser.description != helptext:
        lines += [parser.description, ""]
    lines += ["```text", parser.format_usage().strip(), "```", ""]
    rows = [_option_row(parser, a) for a in parser._actions
            if not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))]
    if rows:
        lines += ["| argument | meaning | default |", "|---|---|---|", *rows, ""]
    subs = _subcommands(parser)
    if subs:
        lines += ["Subcommands: " + ", ".join(f"`{path} {name}`" for name, _, _ in subs) + ".", ""]
    for name, sub_help, sub in subs:
        lines += _command_section(f"{path} {name}", sub_help, sub)
    return lines


def cli_reference() -> str:
    """Every command and option of ``pounding``, from its argument parser, as Markdown."""
    from pounding.cli import build_parser

    parser = build_parser(None)
    lines = ["# Command-line reference", "",
             "Generated from the argument parser itself when the site is built, so it lists exactly what "
             "`pounding` accepts; `pounding COMMAND --help` prints the same.  What the commands do, with "
             "examples, errors and exit codes: [the command guide](../cli.md).", "",
             "```text", parser.format_usage().strip(), "```", "",
             "| option | meaning | default |", "|---|---|---|",
             *[_option_row(parser, a) for a in parser._actions
               if not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))], "",
             "| command | what it does |", "|---|---|",
             *[f"| [`pounding {name}`](#pounding-{name}) | {_cell(h)} |" for name, h, _ in _subcommands(parser)], ""]
    for name, helptext, sub in _subcommands(parser):
        lines += _command_section(f"pounding {name}", helptext, sub)
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- #
# The model files
# --------------------------------------------------------------------------- #


def _models_in(annotation: object) -> list[type[BaseModel]]:
    """The pydantic models an annotation names (inside unions, lists, Annotated...)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    found: list[type[BaseModel]] = []
    for arg in typing.get_args(annotation):
        found += [m for m in _models_in(arg) if m not in found]
    return found


def _type_name(annotation: object) -> str:
    """A reader's name for a field's type: number, integer, text, true/false, list of ..., mapping."""
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is typing.Annotated:
        return _type_name(args[0])
    if origin in (typing.Union, types.UnionType):
        names = [_type_name(a) for a in args if a is not type(None)]
        return " or ".join(dict.fromkeys(names))
    if origin in (list, tuple):
        inner = [_type_name(a) for a in args if a is not Ellipsis]
        return "list of " + (" or ".join(dict.fromkeys(inner)) or "values")
    if origin is dict:
        return "mapping"
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return f"mapping ([{_title(annotation)}](#{_anchor(annotation)}))"
    return {float: "number", int: "integer", str: "text", bool: "true/false"}.get(annotation, "any")  # type: ignore[call-overload]


def _title(model: type[BaseModel]) -> str:
    return model.__name__


def _anchor(model: type[BaseModel]) -> str:
    return model.__name__.lower()


def _default(info) -> str:
    if info.is_required():
        return "required"
    value = info.default if info.default is not PydanticUndefined else info.default_factory()
    if isinstance(value, BaseModel):
        return f"the defaults of [{_title(type(value))}](#{_anchor(type(value))})"
    return "—" if value is None else f"`{value}`"


def _model_table(model: type[BaseModel], heading: str) -> list[str]:
    lines = [f"### {_title(model)} {{#{_anchor(model)}}}", "", heading, "",
             "| key | type | default | meaning |", "|---|---|---|---|"]
    for key, info in model.model_fields.items():
        if key == "parameters" and not info.description:   # a law's own keys, written beside `law:`
            lines.append(f"| (the law's keys) | | | the keys of the chosen `law`, in this same mapping: "
                         f"{', '.join(f'[{_title(m)}](#{_anchor(m)})' for m in _models_in(info.annotation))} |")
            continue
        lines.append(f"| `{key}` | {_cell(_type_name(info.annotation))} | {_cell(_default(info))} | "
                     f"{_cell(info.description or '')} |")
    return lines + [""]


def _walk(roots: list[tuple[type[BaseModel], str]], skip: frozenset = frozenset()) -> list[tuple[type[BaseModel], str]]:
    """Every model reachable from *roots* through its fields, each once, with where it is used (those
    in *skip*, listed elsewhere, left out)."""
    seen: dict[type[BaseModel], str] = {}
    queue = list(roots)
    while queue:
        model, where = queue.pop(0)
        if model in seen or model in skip:
            continue
        seen[model] = where
        children = [*(m for info in model.model_fields.values() for m in _models_in(info.annotation)),
                    *getattr(model, "CHILDREN", {}).values()]
        queue += [(child, f"Used in [{_title(model)}](#{_anchor(model)}).") for child in children]
    return list(seen.items())


def yaml_reference() -> str:
    """Every key of a model file, from the pydantic models that validate it, as Markdown."""
    from pounding.contact.laws import LAWS
    from pounding.contact.links import LINK_LAWS
    from pounding.hysteresis import HYSTERESES
    from pounding.model import plan_schema, schema

    registries = (("Contact laws", "The keys of a contact entry with `law: NAME`, besides those of "
                   "[ContactEntry](#contactentry).", "law", LAWS),
                  ("Link laws", "The keys of a link entry with `law: NAME`, besides those of "
                   "[LinkEntry](#linkentry).", "law", LINK_LAWS),
                  ("Storey hysteresis", "The keys of a storey's `hysteresis:` mapping with `model: NAME`.",
                   "model", HYSTERESES))
    listed = frozenset(m for *_, registry in registries for m in registry.values())

    lines = ["# Model file reference", "",
             "Every key a model file may hold, generated from the validating schema when the site is built: "
             "the type, the default (\"required\" where there is none) and the meaning with its units "
             "(SI throughout).  The guide with examples is [models/README.md](../models/README.md); a "
             "plan model's keys are explained in [plan models](../plan-models.md).", "",
             "## A model with floors along one line", ""]
    planar = _walk([(schema.TopLevel, "The top level of a model file.")], listed)
    for model, where in planar:
        lines += _model_table(model, where)
    lines += ["## A model with floors in plan", "",
              "A model whose buildings have a `plan:` mapping; the mappings shared with the planar "
              "model are described above.", ""]
    shown = {m for m, _ in planar} | listed
    for model, where in _walk([(plan_schema.PlanModelEntry, "The top level of a plan model file.")], listed):
        if model not in shown:
            lines += _model_table(model, where)
    for title, intro, key, registry in registries:
        lines += [f"## {title}", "", intro, ""]
        for name, model in registry.items():
            lines += _model_table(model, f"`{key}: {name}`.")
            shown.add(model)
        for model, where in _walk([(m, "") for m in registry.values()]):   # their nested mappings
            if model not in shown:
                lines += _model_table(model, where)
                shown.add(model)
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- #
# The archive
# --------------------------------------------------------------------------- #


def archive_variables() -> dict[str, dict[str, object]]:
    """name -> {dims, units, long_name, models} of every variable of the shipped models' short runs."""
    import pounding

    found: dict[str, dict[str, object]] = {}
    for name in ARCHIVE_MODELS:
        ds = pounding.simulate(pounding.load_model(ROOT / "models" / name), duration=ARCHIVE_DURATION)
        for var in [*ds.coords, *ds.data_vars]:
            item = ds[var]
            entry = found.setdefault(str(var), {"dims": ", ".join(map(str, item.dims)),
                                                "units": item.attrs.get("units", ""),
                                                "long_name": item.attrs.get("long_name", ""),
                                                "coordinate": var in ds.coords, "models": []})
            entry["models"].append(name.removesuffix(".yaml"))  # type: ignore[union-attr]
    return found


def archive_reference() -> str:
    """Every variable of a run archive with its dimensions, units and long name, as Markdown."""
    variables = archive_variables()
    everywhere = len(ARCHIVE_MODELS)
    lines = ["# Run archive reference", "",
             "Every coordinate and variable of a `pounding run` archive (and of `pounding.simulate`'s "
             "dataset), read when the site is built from short runs of the shipped models "
             f"({', '.join(f'`models/{m}`' for m in ARCHIVE_MODELS)}).  \"in\" names the models whose "
             "archive has it where not all do.  How to read and combine archives: "
             "[results](../results.md).", ""]
    for coordinate in (True, False):
        lines += ["## Coordinates" if coordinate else "## Variables", "",
                  "| name | dimensions | units | long name | in |", "|---|---|---|---|---|"]
        for name, entry in sorted(variables.items()):
            if entry["coordinate"] != coordinate:
                continue
            models = entry["models"]
            where = "all" if len(models) == everywhere else ", ".join(models)  # type: ignore[arg-type]
            lines.append(f"| `{name}` | {_cell(entry['dims'])} | {_cell(entry['units'])} | "
                         f"{_cell(entry['long_name'])} | {_cell(where)} |")
        lines.append("")
    return "\n".join(lines) + "\n"


#: Site path -> generator of each reference page.
PAGES = {"reference/cli.md": cli_reference, "reference/yaml.md": yaml_reference,
         "reference/archive.md": archive_reference}


def main(argv: list[str]) -> int:
    """``python docs/gen_reference.py DIR``: write the reference pages into DIR."""
    out = Path(argv[0] if argv else "reference-pages")
    for path, make in PAGES.items():
        target = out / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(make(), encoding="utf-8")
        print(f"wrote {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
