"""What a format declares about itself, once, in ``modelkit/formats/<name>/declare.py``.

Data only (no reader, writer, numpy or XML parser is imported): the CLI builds its format choices
from these at startup, collected by :mod:`modelkit.formats.registry`. Immutable records; NamedTuple
rather than a frozen dataclass, which takes about 1.3 ms per class to create (measured, Python 3.11):
they are on the path of every ``modelkit`` command's startup.
"""

from __future__ import annotations

from typing import NamedTuple


class OutputDeclaration(NamedTuple):
    """How modelkit writes a format (``convert --to NAME``)."""

    writer: str  # "module:function", imported on first use: write(robot, ctx) -> bytes
    suffix: str  # what `convert -o DIR --to NAME` names the files
    suffixes: tuple[str, ...]  # output file suffixes that select this format
    tracks_native: bool = False  # the format holds pseudo continuous tracks itself
    auto_wheel: str = "cylinder"  # the wheel collision `--wheel-collision auto` writes: cylinder or sphere
    sites_native: bool = False  # the format holds MJCF sites (named frames on a body) itself
    frames_native: bool = False  # the format holds SDF <frame>s (named poses on a link) itself
    pair_exclusions_native: bool = False  # the format excludes one link pair's contacts (SRDF pairs)
    handles: frozenset[str] = frozenset()  # other formats' robot/link extras keys its writer notes itself
    handles_joint: frozenset[str] = frozenset()  # the same for joint extras keys
    walks_extras: bool = False  # its writer notes every other format's robot extras key itself
    # how a user stands a free robot of this format on the ground, "{z}" the root frame's height (MK884);
    # empty: the format does it itself (MJCF's home key, MK882)
    spawn: str = ""
    places_root: bool = False  # the file places the root at the model's root pose (else the user spawns it)


class ExtrasDeclaration(NamedTuple):
    """The keys a format's reader keeps in ``extras`` (data only the format itself reads and writes) that
    another target's writer meets when it walks ``extras`` to say what it leaves out.

    ``quiet`` (robot) and ``quiet_link`` (link) keys carry nothing that target misses: bookkeeping, or
    data the model's own fields already hold. ``dropped`` gives each other robot key the note's code
    and its words ("MJCF tendons"); ``dropped_link`` and ``dropped_joint`` do the same for link and joint
    keys, and ``convert`` notes those for every other target (:func:`modelkit.convert.api.prepare`)
    unless the target's writer handles the key itself (``OutputDeclaration.handles``). ``convert`` also
    notes ``dropped`` robot keys for a target whose writer does not walk ``extras`` itself
    (``OutputDeclaration.walks_extras``), except ``partly_carried`` ones (MJCF cameras: those on links
    are the model's devices), which only a walking writer can count. The owning format says this once,
    so no writer lists another format's keys.
    """

    quiet: frozenset[str] = frozenset()
    quiet_link: frozenset[str] = frozenset()
    dropped: tuple[tuple[str, str, str], ...] = ()  # (key, code, what)
    dropped_link: tuple[tuple[str, str, str], ...] = ()  # the same for link keys, noted by convert itself
    dropped_joint: tuple[tuple[str, str, str], ...] = ()  # and for joint keys
    partly_carried: frozenset[str] = frozenset()  # dropped robot keys the model's fields carry in part
    # (key, ((entry, value), ...)): entries of a dropped dict-valued key that say only the format's default
    # (an SDF link's <gravity>true</gravity>): nothing is lost, so a note leaves them out
    defaults: tuple[tuple[str, tuple[tuple[str, object], ...]], ...] = ()
    # (key, targets, left): dropped keys another target's writer carries anyway, through the owning
    # format's own code (an SDF link's flags in a URDF's <gazebo reference> blocks, which libsdformat
    # copies back); ``left`` is "" when all of it is carried, else "module:function" giving, from the
    # value and its link (joint, robot), what those targets still drop (the note names that part)
    carried_to: tuple[tuple[str, tuple[str, ...], str], ...] = ()


class FormatDeclaration(NamedTuple):
    """A model format: how modelkit recognises and reads it, and (``output``) whether and how it writes it."""

    name: str  # the --input-format (and --to) name
    description: str
    suffixes: tuple[str, ...]  # input file suffixes that select this format
    reader: str  # "module:function", imported on first use: read(path, options, display) -> ReadResult
    root_tags: tuple[str, ...] = ()  # top XML elements that identify it (an .xml file)
    output: OutputDeclaration | None = None  # None: modelkit reads it but does not write it
    extras: ExtrasDeclaration = ExtrasDeclaration()  # its own extras keys, as other targets see them
