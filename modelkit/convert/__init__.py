"""Conversion: the writers' shared machinery (notes, numbers, output folder, meshes) and the
``convert`` pipeline (read, check, write every robot of every input into one output folder)."""

from modelkit.convert.api import ConversionResult, convert, write
from modelkit.convert.notes import ConversionNote
from modelkit.convert.options import WriteOptions

__all__ = ["ConversionNote", "ConversionResult", "WriteOptions", "convert", "write"]
