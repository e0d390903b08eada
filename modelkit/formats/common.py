"""What every reader takes and returns: reading options and the read result."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from modelkit.diagnostics import Diagnostic
from modelkit.model import Robot
from modelkit.resources import Resolver
from modelkit.textio import (
    DEFAULT_EXPANSION_LIMIT,
    DEFAULT_MAX_BYTES,
    DEFAULT_MAX_LINKS,
    DEFAULT_MAX_LIST_ITEMS,
    OpenedFile,
)


@dataclass
class ReadOptions:
    """Options shared by all readers; each reader uses the ones that concern its format.

    ``xacro_args`` are xacro's ``key:=value`` arguments. ``legacy_xacro`` says how pre-Jade xacro
    (``<property>``, ``<include>`` and macro calls without the ``xacro:`` prefix) is treated: None
    detects it and expands it with a warning per construct, True always expands it, False expands
    as current xacro does (legacy constructs stay in the output and are reported as errors).
    """

    resolver: Resolver = field(default_factory=Resolver)
    materials_path: Path | None = None
    faithful_extrusion: bool = True
    check_resources: bool = True
    max_bytes: int = DEFAULT_MAX_BYTES
    expansion_limit: int = DEFAULT_EXPANSION_LIMIT
    max_list_items: int = DEFAULT_MAX_LIST_ITEMS
    max_links: int = DEFAULT_MAX_LINKS
    xacro_args: dict[str, str] = field(default_factory=dict)
    legacy_xacro: bool | None = None
    srdf: Path | None = None  # MoveIt's SRDF beside the model: its group_state gives the home pose
    home: str | None = None  # the group_state to use (None: home, ready or default; modelkit.formats.srdf)


@dataclass
class ReadResult:
    """A reader's result: the robot (None when nothing usable was read) and what was found.

    A file may hold several robots (an SDF world with several models): ``robot`` is the first and
    ``more`` holds the others, in document order.
    """

    robot: Robot | None
    diagnostics: list[Diagnostic]
    more: list[Robot] = field(default_factory=list)
    # Every regular file the read opened (filled by :func:`modelkit.formats.read_model`): the model,
    # its includes, resources, materials and meshes; ``convert`` never writes over any of them.
    opened: list[OpenedFile] = field(default_factory=list)

    @property
    def robots(self) -> list[Robot]:
        return ([self.robot] if self.robot is not None else []) + list(self.more)
