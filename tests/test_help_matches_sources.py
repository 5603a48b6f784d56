"""Help cannot lag behind what the readers take: every command's robot argument shows the
one shared description of robot sources, and every command that reads a robot takes
the shared source options (``--floating-base``, ``--asset-root``, ...)."""

from __future__ import annotations

import argparse

from robotwright.cli import build_parser
from robotwright.cli.options import ROBOT_SOURCE_HELP

#: Positional arguments that name a robot to read.
ROBOT_ARGS = {"robot", "robots", "src", "path"}


def _commands() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    out = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            out.update(action.choices)
    return out


def test_every_robot_argument_shows_the_shared_help():
    checked = []
    for name, command in _commands().items():
        for action in command._actions:
            if not action.option_strings and action.dest in ROBOT_ARGS:
                assert ROBOT_SOURCE_HELP in (action.help or ""), (name, action.help)
                checked.append(name)
    assert {"export", "convert", "info", "validate", "compose", "isaaclab-cfg"} <= set(checked), (
        checked
    )


def test_commands_reading_a_robot_take_the_shared_options():
    for name, command in _commands().items():
        positional = {a.dest for a in command._actions if not a.option_strings}
        if positional & ROBOT_ARGS or name in ("render", "view"):
            flags = set(command._option_string_actions)
            assert {"--floating-base", "--asset-root", "--root-body"} <= flags, name
