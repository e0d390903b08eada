"""What a writer gets besides the robot: options, the notes sink and the mesh exporter."""

from __future__ import annotations

from dataclasses import dataclass

from modelkit.convert.meshes import MeshExporter
from modelkit.convert.notes import NoteSink
from modelkit.convert.options import WriteOptions
from modelkit.diagnostics import SourceLocation


@dataclass
class WriteContext:
    options: WriteOptions
    notes: NoteSink
    meshes: MeshExporter
    model_relpath: str  # the model file's path inside the output folder

    def note(self, code: str, message: str, source: SourceLocation | None = None,
             target: str | None = None) -> None:
        self.notes.note(code, message, source, target)

    def rename(self, kind: str, old: str, new: str, why: str, source: SourceLocation | None = None,
               target: str | None = None) -> None:
        """A deterministic rename the target forced (MK800), kept as data for round-trip checks."""
        self.notes.rename(kind, old, new, why, source, target)
