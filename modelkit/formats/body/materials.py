"""Choreonoid contact materials: the table that gives link `material:` names their meaning.

The default table is Choreonoid's own ``share/default/materials.yaml`` (shipped in
``modelkit/data``); ``--materials FILE`` selects another one with the same layout.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.formats.body.values import number, scalar_text
from modelkit.textio import real_path
from modelkit.yamltree import YMap, YScalar, YSeq, parse_yaml, read_text

DEFAULT_MATERIALS = Path(__file__).resolve().parents[2] / "data" / "materials.yaml"


@dataclass(frozen=True)
class ContactMaterial:
    name: str
    roughness: float = 0.5
    viscosity: float = 1.0
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class ContactPair:
    names: tuple[str, str]
    static_friction: float = 0.5
    dynamic_friction: float = 0.5
    restitution: float = 0.0


@dataclass
class MaterialTable:
    path: str
    materials: dict[str, ContactMaterial] = field(default_factory=dict)
    pairs: list[ContactPair] = field(default_factory=list)

    def knows(self, name: str) -> bool:
        return name in self.materials or name.lower() == "default"


_CACHE: dict[str, MaterialTable] = {}


def load_materials(path: Path | None, sink: DiagnosticSink) -> MaterialTable:
    """Read a materials file; problems go to ``sink`` (MK511) and give an empty table."""
    target = path or DEFAULT_MATERIALS
    key = str(real_path(target)) if os.path.exists(target) else str(target)
    if key in _CACHE:
        return _CACHE[key]
    table = MaterialTable(str(target))
    local = DiagnosticSink()
    text = read_text(target, local)
    doc = parse_yaml(text, str(target), local) if text is not None else None
    root = doc.root if doc else None
    entries = root.get("materials") if isinstance(root, YMap) else None
    if not isinstance(entries, YSeq):
        sink.emit(
            "MK511",
            f"cannot read contact materials from {target}: no `materials` list",
            SourceLocation(str(target)),
        )
        for d in local.items:
            sink.add(d)
        return table
    for item in entries.items:
        if not isinstance(item, YMap):
            continue
        name = scalar_text(item.get("name"))
        if not name:
            continue
        extra = {
            k: v.value
            for k, v in item.items()
            if isinstance(v, YScalar) and k not in ("name", "roughness", "viscosity")
        }
        table.materials[name] = ContactMaterial(
            name,
            0.5 if number(item.get("roughness")) is None else float(number(item.get("roughness")) or 0.0),
            1.0 if number(item.get("viscosity")) is None else float(number(item.get("viscosity")) or 0.0),
            extra,
        )
    pairs = root.get("contact_materials", "contactMaterials") if isinstance(root, YMap) else None
    if isinstance(pairs, YSeq):
        for item in pairs.items:
            if not isinstance(item, YMap):
                continue
            names = item.get("materials")
            if not isinstance(names, YSeq) or len(names.items) < 2:
                continue
            texts = [scalar_text(n) or "" for n in names.items]
            friction = number(item.get("friction"))
            static = number(item.get("static_friction", "staticFriction"))
            dynamic = number(item.get("dynamic_friction", "dynamicFriction"))
            restitution = number(item.get("restitution"))
            for i in range(len(texts)):
                for j in range(i + 1, len(texts)):
                    table.pairs.append(
                        ContactPair(
                            (texts[i], texts[j]),
                            static if static is not None else (friction if friction is not None else 0.5),
                            dynamic if dynamic is not None else (friction if friction is not None else 0.5),
                            restitution if restitution is not None else 0.0,
                        )
                    )
    _CACHE[key] = table
    return table
