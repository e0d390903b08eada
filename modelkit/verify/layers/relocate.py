"""A file given to ``verify`` (``--mjcf``, ``--urdf``, ``--sdf``), copied into the output folder so that
``--inject`` edits the copy and never the user's file.

The copy sits in another folder than the original, so every relative reference in it is made
absolute against the original's folder and the engines load the same meshes, textures and included
files: URDF ``filename`` attributes (meshes, textures), SDF ``<uri>`` texts, MJCF ``<include file>``
and asset ``file`` attributes, and MJCF's ``<compiler meshdir/texturedir/assetdir>`` (the folder they
name, or the original's own folder when there is none, is written as an absolute ``meshdir`` and
``texturedir``). References with a scheme (``package://``, ``model://``, ``file://``) and absolute
paths are kept.
"""

from __future__ import annotations

import os
from pathlib import Path

from lxml import etree

from modelkit.verify.layers.inject import file_format, save

_MJCF_DIRS = ("meshdir", "texturedir")
_MJCF_MODEL_RELATIVE = ("include", "model")  # file attributes resolved against the model's folder


def relocated_copy(path: Path, folder: Path) -> Path:
    """Copy ``path`` into ``folder`` (created) with its relative references made absolute; the copy."""
    path = Path(path)
    origin = path.resolve().parent
    parser = etree.XMLParser(remove_blank_text=False, remove_comments=False, resolve_entities=False,
                             no_network=True, huge_tree=False)
    tree = etree.parse(str(path), parser)
    root = tree.getroot()
    kind = file_format(path)
    if kind == "urdf":
        for element in root.iter("mesh", "texture"):
            _absolute_attribute(element, "filename", origin)
    elif kind == "sdf":
        for element in root.iter("uri"):
            if element.text and _relative(element.text.strip()):
                element.text = str(origin / element.text.strip())
    else:
        _mjcf(root, origin)
    folder.mkdir(parents=True, exist_ok=True)
    copy = folder / path.name
    temporary = copy.with_name(f".{copy.name}.tmp")
    save(temporary, tree, like=path)
    os.replace(temporary, copy)
    return copy


def _mjcf(root: etree._Element, origin: Path) -> None:
    compilers = list(root.iter("compiler"))
    assetdir = next((str(c.get("assetdir")) for c in compilers if c.get("assetdir")), "")
    dirs = {name: next((str(c.get(name)) for c in compilers if c.get(name)), assetdir) for name in _MJCF_DIRS}
    for compiler in compilers:
        for name in ("assetdir", *_MJCF_DIRS):
            if name in compiler.attrib:
                del compiler.attrib[name]
    compiler = compilers[0] if compilers else etree.SubElement(root, "compiler")
    if not compilers:
        root.insert(0, compiler)
    for name, value in dirs.items():
        compiler.set(name, str(origin / value) if _relative(value) else value)
    for element in root.iter(*_MJCF_MODEL_RELATIVE):
        _absolute_attribute(element, "file", origin)


def _absolute_attribute(element: etree._Element, name: str, origin: Path) -> None:
    value = element.get(name)
    if value and _relative(value):
        element.set(name, str(origin / value))


def _relative(reference: str) -> bool:
    return "://" not in reference and not os.path.isabs(reference)
