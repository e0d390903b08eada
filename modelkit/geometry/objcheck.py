"""A fast verdict on a Wavefront OBJ file: would :func:`modelkit.geometry.meshfiles.load_mesh` load it?

``modelkit validate`` only needs to know whether a mesh file can be used, not its triangles. Reading an
OBJ file through trimesh costs the import of trimesh (about half a second) and trimesh's texture
bookkeeping (``unmerge_faces``); this module decides the same question in plain Python, without numpy
or trimesh.

:func:`obj_problem` follows what ``meshfiles._load_obj`` does with trimesh's ``load_obj`` (5.x, with
``group_material=False, skip_materials=True, maintain_order=True``) followed by ``meshfiles._finish``
without fragment and metadata, step by step: the same text normalisation (``\\r\\n``, line continuations),
the same way of finding the ``v``/``vt``/``vn`` rows and the face chunks (split at ``usemtl``), the
vectorised or per-line reading of the face lines, the vertex masks (all vertices, or the vertices up to the
largest index when there are texture coordinates or normals), and in the end the checks of ``_load_obj``
and ``_finish`` in their order. The messages are the ones ``load_mesh`` gives.

Most of a file is numbers, and reading each one in Python costs more than the rest. Where the text is
ASCII, the rows and face lines are first judged by their shapes (every digit read as 0; a file has a
handful of distinct shapes among its hundreds of thousands of lines): each shape is read once, and the
faces keep only their smallest and largest vertex index unless those cannot decide. What the shapes
cannot settle (rows of different lengths, long digit runs, large exponents) is read number by number.

Whatever it cannot decide exactly and cheaply (a number numpy and Python might read differently, an
unusual white-space character, a face token that is not ``a``, ``a/b``, ``a//c`` or ``a/b/c`` with plain
integers, an error whose text comes from numpy) gives :data:`UNDECIDED`: the caller then loads the file.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from itertools import pairwise

__all__ = ["UNDECIDED", "obj_problem", "obj_verdict"]

#: Returned by :func:`obj_problem` when only the full loader can tell.
UNDECIDED = "UNDECIDED\tthe fast OBJ check cannot decide; load the file"

# Characters Python's str.split/splitlines and C's isspace (numpy's number reader) do not agree on
# (or that Python treats as a line break): a file with any of them is left to the full loader.
_ODD_SPACE = re.compile("[\r\x0b\x0c\x1c-\x1f\x85\xa0\u1680\u2000-\u200a\u2028\u2029\u202f\u205f\u3000]")
# vertex rows made only of these characters are read alike by Python's float() and numpy
_NOT_DECIMAL_CHAR = re.compile(r"[^0-9eE+\-. \t]")
_NUMBER_TOKEN = re.compile(r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|nan|inf|infinity)", re.IGNORECASE)
# a token that is not a number and does not start like numpy's NaN/infinity spellings ("nan(...)")
_NAN_INF_START = re.compile(r"[+-]?(?:nan|inf)", re.IGNORECASE)
# numpy's message when np.fromstring meets something that is not a number
_NUMPY_UNMATCHED = "string or file could not be read to its end due to unmatched data"
_INT_LIMIT = 2**62  # larger indices: numpy's int64 reading might wrap or saturate
_INT_DIGITS = 18  # a run of at most this many digits is below _INT_LIMIT

# The fast paths below judge numbers by their shape: every digit read as 0 ("-12.5e3" is "-00.0e0"). Whether
# Python (and so numpy, for these characters) reads a token as a number depends on its shape alone, and a
# file written by one exporter has a handful of shapes among its millions of numbers.
_DIGITS_TO_ZERO = bytes.maketrans(b"123456789", b"000000000")
_DECIMAL_BYTES = b"0123456789eE+-. \t"
_FACE_BYTES = b"0123456789/- \t\n"  # face lines made only of these: integers, slashes, blanks
_ODD_ASCII_SPACE = "\r\x0b\x0c\x1c\x1d\x1e\x1f"
# trimesh's rows: the rest of the line after each "\n<kind> " (its split and first-line comprehension)
_ROWS = {k: re.compile(f"\n{k} ([^\n]*)") for k in ("v", "vt", "vn")}
# trimesh's face lines: the rest of each line starting with "f" (its re.split("^f") and first line)
_FACE_LINE = re.compile("^f([^\n]*)", re.MULTILINE)


class _Undecided(Exception):
    """The fast check cannot decide exactly: load the file."""


class _Malformed(Exception):
    """A ``v``/``vt``/``vn`` row holds something that is not a number (numpy's reader refuses it)."""


@dataclass
class _Vertices:
    rows: int  # rows of trimesh's vertex array
    columns: int  # its columns after trimesh keeps at most three
    first_bad_row: int | None  # first row with a NaN/infinite coordinate among those columns
    text: str = ""  # the text trimesh finds the rows in (its chunk of v/vt/vn lines)


@dataclass
class _Chunk:
    width: int  # vertices per face
    masked_to_max: bool  # the vertex mask is arange(max + 1) (texture or normal indices present)
    count: int  # vertex references
    low: int  # the smallest and largest of them (trimesh's 0-based, negatives kept)
    high: int
    read_faces: Callable[[], list[int]] = field(repr=False)

    @cached_property
    def faces(self) -> list[int]:
        """The vertex indices, row-major, ``width`` per face; read only when the bounds cannot decide."""
        return self.read_faces()


def _chunk_of(faces: list[int], width: int, masked_to_max: bool) -> _Chunk:
    return _Chunk(width, masked_to_max, len(faces), min(faces), max(faces), lambda: faces)


Corners = tuple[tuple[float, float, float], tuple[float, float, float]]


def obj_problem(data: bytes, name: str) -> str | None:
    """None when ``load_mesh`` loads an OBJ file with these bytes (no fragment, no metadata), else
    ``"MK501\\t<message>"`` with the message of its :class:`MeshLoadError`, or :data:`UNDECIDED`."""
    return obj_verdict(data, name, corners=False)[0]


def obj_verdict(data: bytes, name: str, corners: bool = True) -> tuple[str | None, Corners | None]:
    """:func:`obj_problem`, and with ``corners``, for a file that loads, the lowest and highest corner of
    the vertices ``load_mesh`` keeps (None when they cannot be had cheaply: rows of different lengths,
    fewer than three columns)."""
    if not data.strip():
        return f"MK501\t{name} is empty", None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    if "\x00" in text:
        return f"MK501\t{name} contains NUL bytes: not a text OBJ file", None
    # trimesh: leading/trailing newline, \r\n -> \n, backslash continuations merged
    text = "\n{}\n".format(text.strip().replace("\r\n", "\n")).replace("\\\n", "")
    if any(c in text for c in _ODD_ASCII_SPACE) if text.isascii() else _ODD_SPACE.search(text):
        return UNDECIDED, None
    try:
        verts, has_normals = _vertices(text)
        if verts is None:  # trimesh returns no geometry
            return f"MK501\t{name} contains no faces: not a usable OBJ file", None
        chunks = [_chunk(c, has_normals) for c in _face_chunks(text)]
        problem, kept_rows = _verdict(verts, chunks, name)
    except _Malformed:
        return f"MK501\t{name}: malformed OBJ ({_NUMPY_UNMATCHED})", None
    except _Undecided:
        return UNDECIDED, None
    return problem, (_corners(verts, kept_rows) if problem is None and corners else None)


# ---- vertices (trimesh.exchange.obj._parse_vertices) ------------------------------------------


def _vertices(text: str) -> tuple[_Vertices | None, bool]:
    """The vertex array trimesh builds (None when it has none) and whether it finds ``vn`` rows."""
    starts = {k: text.find(f"\n{k} ") for k in ("v", "vt", "vn")}
    if not any(s >= 0 for s in starts.values()):
        return None, False
    ends = [text.find("\n", text.rfind(f"\n{k} ") + 2 + len(k)) for k, s in starts.items() if s >= 0]
    ends = [e for e in ends if e >= 0]
    if not ends:
        raise _Undecided
    start = min(s for s in starts.values() if s >= 0)
    chunk = text[start : max(ends)].replace("+e", "e").replace("-e", "e")
    lines = _zeroed_lines(chunk) if chunk.isascii() else None
    verts: _Vertices | None = None
    for k, s in starts.items():
        if s < 0:
            continue
        table = _rows_by_shape(lines, k, chunk) if lines is not None else None
        if table is None:
            rows = _ROWS[k].findall(chunk)
            if not rows:
                raise _Undecided
            table = _number_rows(rows)
        if k == "v":
            verts = table
            verts.text = chunk
    return verts, starts["vn"] >= 0


def _floats(tokens: list[str]) -> list[float]:
    """The numbers of ``tokens`` when numpy and Python read every one of them alike."""
    try:
        return list(map(float, tokens))
    except ValueError:
        raise _Undecided from None


def _number_rows(rows: list[str]) -> _Vertices:
    """Rows of numbers as trimesh reads them: one ``np.fromstring`` of all rows, reshaped to
    (rows, numbers of the first row) when the count fits, else row by row clipped to the shortest."""
    joined = " ".join(rows)
    per_row = len(rows[0].split())
    tokens = joined.split()
    try:
        if _NOT_DECIMAL_CHAR.search(joined) and not all(_NUMBER_TOKEN.fullmatch(t) for t in tokens):
            raise ValueError
        values = list(map(float, tokens))
    except ValueError:
        odd = [t for t in tokens if not _NUMBER_TOKEN.fullmatch(t)]
        if any(not _NAN_INF_START.match(t) for t in odd):
            raise _Malformed from None  # numpy's np.fromstring stops at it (numpy >= 2: ValueError)
        raise _Undecided from None
    if len(values) == len(rows) * per_row:
        columns = min(per_row, 3)
        bad: int | None = None
        if not all(map(math.isfinite, values)):
            for i, x in enumerate(values):
                if not math.isfinite(x) and i % per_row < columns:
                    bad = i // per_row
                    break
        return _Vertices(len(rows), columns, bad)
    # the row-by-row fallback: empty rows vanish (str.splitlines), rows are clipped to the shortest
    lines = [r.split() for r in rows if r]
    count = min(len(t) for t in lines)
    columns = min(count, 3)
    bad = next((r for r, t in enumerate(lines) if not all(map(math.isfinite, _floats(t[:columns])))), None)
    return _Vertices(len(lines), columns, bad)


def _zeroed_lines(text: str) -> set[bytes]:
    """The distinct lines of an ASCII ``text`` with every digit written as 0."""
    return set(text.encode("ascii").translate(_DIGITS_TO_ZERO).split(b"\n"))


def _rows_by_shape(lines: set[bytes], kind: str, chunk: str) -> _Vertices | None:
    """trimesh's table of the ``kind`` rows of ``chunk``, judged from the shapes of its lines alone when
    every row holds as many plain decimal numbers, each surely finite; None otherwise (the caller then
    reads every number). A number that is no number is :class:`_Malformed` whatever its digits."""
    prefix = f"{kind} ".encode()
    rows = [line[len(prefix) :] for line in lines if line.startswith(prefix)]
    if not rows or any(row.translate(None, _DECIMAL_BYTES) for row in rows):
        return None
    tokens = [row.split() for row in rows]
    numbers = set().union(*tokens)
    for number in numbers:
        try:
            float(number)
        except ValueError:
            raise _Malformed from None  # numpy's np.fromstring stops at it (numpy >= 2: ValueError)
    if len({len(t) for t in tokens}) != 1 or not all(map(_surely_finite, numbers)):
        return None
    return _Vertices(chunk.count(f"\n{kind} "), min(len(tokens[0]), 3), None)


def _surely_finite(shape: bytes) -> bool:
    """A number of this shape is finite whatever its digits (below 1e100 times 1e99)."""
    mantissa, _, exponent = shape.lower().partition(b"e")
    return len(mantissa) <= 100 and len(exponent.lstrip(b"+-")) <= 2


# ---- faces (trimesh.exchange.obj._preprocess_faces and load_obj) --------------------------------


def _face_chunks(text: str) -> list[str]:
    """The face chunks trimesh reads, in its order (one per ``usemtl``-delimited part with faces)."""
    f_start = len(text)
    for st in ("\nusemtl ", "\no ", "\nf ", "\ng ", "\ns "):
        search = text.find(st, 0, f_start)
        if 0 <= search < f_start:
            f_start = search
    f_end = text.find("\n", text.rfind("\nf ") + 3)
    f_chunk = text[f_start:f_end] if f_end >= 0 else text[f_start:]
    splits = sorted({0, len(f_chunk), *(m.start(0) for m in re.finditer("usemtl ", f_chunk))})
    chunks = []
    for start, end in pairwise(splits):
        chunk = f_chunk[start:end].strip() + "\n"
        if chunk.startswith(("o ", "usemtl", "g ")):
            chunk = chunk.split("\n", 1)[1]
        if chunk.startswith("f ") or "\nf" in chunk:
            chunks.append(chunk)
    return chunks


def _ints(text: bytes) -> list[int]:
    try:
        values = list(map(int, text.split()))
    except ValueError:
        raise _Undecided from None
    if values and (max(values) >= _INT_LIMIT or min(values) <= -_INT_LIMIT):
        raise _Undecided
    return values


def _chunk(chunk: str, has_normals: bool) -> _Chunk:
    """The vertex indices of one face chunk, read as trimesh does (vectorised when every face line has
    the same number of integers, else line by line with quads and polygons fanned into triangles)."""
    block = _face_block(chunk)
    if block.translate(None, _FACE_BYTES):
        raise _Undecided  # a character that is not a digit, slash, minus or blank
    shapes = _line_shapes(block)
    if shapes is None:  # long digit runs: every index is read
        face_lines = block.split(b"\n")
        columns = [len(f.replace(b"/", b" ").split()) for f in face_lines]
        if all(c == columns[0] for c in columns):
            return _vectorised(block, columns[0], has_normals, check_ints=True)
        return _per_line(face_lines, has_normals)
    counts = {len(s.replace(b"/", b" ").split()) for s in shapes}
    if len(counts) != 1:
        return _per_line_by_shape(block, shapes, has_normals)
    if any(t not in (b"0", b"-0") for s in shapes for t in s.replace(b"/", b" ").split()):
        raise _Undecided  # a token that is not a plain integer (numpy and int() may differ)
    return _vectorised(block, counts.pop(), has_normals, check_ints=False)


def _face_block(chunk: str) -> bytes:
    """The rest of every line that starts with ``f`` (trimesh's ``re.split("^f")`` and first line), one per
    line; :class:`_Undecided` when one of them is not ASCII. trimesh strips each line; blanks at the ends
    change nothing here, since every use of these lines splits them at blanks."""
    if not chunk.isascii():
        lines = [line.strip() for line in _FACE_LINE.findall(chunk)]
        if not all(line.isascii() for line in lines):
            raise _Undecided
        return "\n".join(lines).encode("ascii")
    pieces = (b"\n" + chunk.encode("ascii")).split(b"\nf")[1:]
    return b"\n".join([piece.split(b"\n", 1)[0] for piece in pieces])


def _line_shapes(block: bytes) -> set[bytes] | None:
    """The distinct face lines of ``block`` with every run of digits written as one 0; None when a run is
    longer than :data:`_INT_DIGITS` (the indices are then read one by one)."""
    data = block.translate(_DIGITS_TO_ZERO)
    if b"0" * (_INT_DIGITS + 1) in data:
        return None
    return {_one_zero_per_run(line) for line in set(data.split(b"\n"))}


def _one_zero_per_run(line: bytes) -> bytes:
    while b"00" in line:
        line = line.replace(b"00", b"0")
    return line


def _vectorised(block: bytes, columns: int, has_normals: bool, check_ints: bool) -> _Chunk:
    """One face chunk whose lines all hold ``columns`` integers; ``check_ints`` when the tokens' shapes
    were not checked (every value is then read and bounded)."""
    sample = block.split(b"\n", 1)[0].decode("ascii")
    joined = block.replace(b"/", b" ")
    if check_ints:
        _ints(joined)
    group_count = len(sample.strip().split())
    if columns == 0 or group_count == 0 or columns % group_count:
        raise _Undecided  # numpy errors or trimesh's slicing of mixed token forms
    per_ref = columns // group_count
    references = joined.split()[::per_ref]
    distinct = list(map(int, set(references)))

    def read_faces() -> list[int]:
        return [_zero_based(int(t)) for t in references]

    tex = norm = False
    if per_ref == 2:
        count = "".join(i.strip("/") for i in sample.split()).count("/")
        if count == columns:  # a//c
            norm = True
        elif count == columns // 2:  # a/b
            tex = True
    elif per_ref == 3:  # a/b/c
        tex = norm = True
    # _zero_based keeps the order of indices: the bounds are those of the raw ones, shifted
    return _Chunk(group_count, tex or (norm and has_normals), len(references), _zero_based(min(distinct)),
                  _zero_based(max(distinct)), read_faces)


def _zero_based(index: int) -> int:
    """trimesh's index: 1-based positive indices shifted to 0-based, relative (negative) ones kept."""
    return index - 1 if index > 0 else index


def _per_line(face_lines: list[bytes], has_normals: bool) -> _Chunk:
    v: list[int] = []
    n_vt = n_vn = 0
    for line in face_lines:
        split = line.split()
        k = len(split)
        if k < 3:
            continue  # trimesh skips it
        if k == 4:
            split = [split[0], split[1], split[2], split[2], split[3], split[0]]
        elif k > 4:
            split = [t for i in range(k - 2) for t in (split[0], split[i + 1], split[i + 2])]
        for token in split:
            parts = token.split(b"/")
            try:
                v.append(int(parts[0]))
            except ValueError:
                raise _Undecided from None
            if len(parts) > 1 and _is_int(parts[1]):
                n_vt += 1
            if len(parts) > 2 and _is_int(parts[2]):
                n_vn += 1
    if not v or max(v) >= _INT_LIMIT or min(v) <= -_INT_LIMIT:
        raise _Undecided  # no faces: trimesh fails in numpy (max of an empty array)
    tex = n_vt == len(v)
    norm = n_vn == len(v)
    return _chunk_of([_zero_based(x) for x in v], 3, tex or (norm and has_normals))


# the first part of every token (its vertex index) in face lines whose tokens are known to start with one
_FIRST_INDEX = re.compile(rb"(?<![^\s])-?[0-9]+")


def _per_line_by_shape(block: bytes, shapes: set[bytes], has_normals: bool) -> _Chunk:
    """:func:`_per_line`'s chunk for a block of lines with different numbers of corners (triangles and
    quads: gb-robot-models' gene01, 650,000 corners, took 1.6 s token by token), whose line ``shapes``
    (every run of digits one 0, :func:`_line_shapes`) are known. Whether a part of a token is an integer
    depends on its shape alone, so each shape is judged once. A line of k ≥ 3 corners gives 3(k − 2)
    references (quads and polygons fanned) and its fan uses every corner, so the count, the smallest
    and the largest index come from the lines' corners without building the fan; the fan itself is
    built only when a relative index needs it (:attr:`_Chunk.faces`)."""
    tex = norm = True
    for shape in shapes:
        tokens = shape.split()
        if len(tokens) < 3:
            continue  # trimesh skips the line
        for token in tokens:
            parts = token.split(b"/")
            if not _is_int(parts[0]):
                raise _Undecided
            tex = tex and len(parts) > 1 and _is_int(parts[1])
            norm = norm and len(parts) > 2 and _is_int(parts[2])
    lines = block.split(b"\n")
    corners = [len(line.split()) for line in lines]
    kept = [line for line, k in zip(lines, corners, strict=True) if k >= 3]
    if not kept:
        raise _Undecided  # no faces: trimesh fails in numpy (max of an empty array)
    indices = list(map(int, _FIRST_INDEX.findall(b"\n".join(kept))))
    count = sum(3 * (k - 2) for k in corners if k >= 3)
    return _Chunk(3, tex or (norm and has_normals), count, _zero_based(min(indices)),
                  _zero_based(max(indices)), lambda: _per_line(lines, has_normals).faces)


def _is_int(token: bytes) -> bool:
    try:
        int(token)
    except ValueError:
        return False
    return True


# ---- the checks of load_obj, _load_obj and _finish, in their order ---------------------------------


def _verdict(verts: _Vertices, chunks: list[_Chunk], name: str) -> tuple[str | None, int]:
    """The verdict, and how many vertex rows (from the first) the loaded mesh keeps."""
    if not chunks:  # trimesh returns a point cloud
        return f"MK501\t{name} contains no faces: not a usable OBJ file", 0
    n = verts.rows
    used_rows: list[int] = []  # vertex rows each chunk keeps
    for c in chunks:
        lo, hi = c.low, c.high
        if c.masked_to_max:  # unmerge_faces(maintain_faces=True): mask arange(max + 1)
            if hi < -1:
                raise _Undecided  # numpy: negative dimensions
            if lo < -(hi + 1) and c.width > 3:  # only the first three of a polygon's corners count
                lo = min(x for i, x in enumerate(c.faces) if i % c.width < 3)
            if lo < -(hi + 1) or hi + 1 > n:
                return f"MK501\t{name}: a face refers to a vertex that does not exist", 0
            used_rows.append(hi + 1)
        else:  # mask of all vertices; indices remapped into [0, n)
            if lo < -n or hi > n - 1:
                return f"MK501\t{name}: a face refers to a vertex that does not exist", 0
            used_rows.append(n)
    # meshfiles._load_obj: trimesh's chunks come out in reverse order; each is reshaped to (-1, 3)
    pieces = list(reversed(list(zip(chunks, used_rows, strict=True))))
    sizes = []
    for _, rows in pieces:
        size = rows * verts.columns
        if size % 3:
            return (f"MK501\tcannot load {name}: ValueError: "
                    f"cannot reshape array of size {size} into shape (3)"), 0
        sizes.append(size // 3)
    total = sum(sizes)
    offset = 0
    n_triangles = 0
    out_of_range = False
    for (c, _), nv in zip(pieces, sizes, strict=True):
        low, high = _remapped_bounds(c, n)
        if c.width == 3:
            n_triangles += c.count // 3
            if low < 0 or high + offset >= total:
                out_of_range = True
        elif c.width > 3:  # polygons with an index outside the vertices are skipped
            w = c.width
            if low >= 0 and high < nv:
                kept = (c.count + w - 1) // w
            else:
                faces = _remapped(c, n)
                kept = sum(1 for i in range(0, len(faces), w) if all(0 <= x < nv for x in faces[i : i + w]))
            n_triangles += kept * (w - 2)
        offset += nv
    if out_of_range:
        return f"MK501\t{name}: face index out of range", 0
    if n_triangles == 0:
        return f"MK501\t{name} contains no triangles", 0
    if verts.first_bad_row is not None and verts.first_bad_row < max(used_rows):
        return f"MK501\t{name} has non-finite vertex coordinates (NaN or infinity)", 0
    return None, max(used_rows)


def _corners(verts: _Vertices, kept_rows: int) -> Corners | None:
    """The lowest and highest corner of the first ``kept_rows`` vertex rows, read as trimesh reads them
    (one ``np.fromstring`` of every ``v`` row); None unless every row holds as many numbers, at least
    three (the loader then reshapes or clips the rows, and only it can tell)."""
    import numpy as np

    rows = _ROWS["v"].findall(verts.text)
    per_row = len(rows[0].split()) if rows else 0
    if per_row < 3 or kept_rows < 1:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            values = np.fromstring(" ".join(rows), sep=" ")  # the reader trimesh uses for these rows
    except ValueError:
        return None
    if values.size != len(rows) * per_row:
        return None
    kept = values.reshape(len(rows), per_row)[:kept_rows, :3]
    low, high = kept.min(axis=0), kept.max(axis=0)
    return (float(low[0]), float(low[1]), float(low[2])), (float(high[0]), float(high[1]), float(high[2]))


def _remapped(c: _Chunk, n: int) -> list[int]:
    """The chunk's vertex indices as trimesh uses them: relative ones counted from the end of the ``n``
    vertices unless the vertex mask is arange(max + 1)."""
    return c.faces if c.masked_to_max else [x + n if x < 0 else x for x in c.faces]


def _remapped_bounds(c: _Chunk, n: int) -> tuple[int, int]:
    """The smallest and largest of :func:`_remapped`, from the chunk's bounds when no index is relative."""
    if c.masked_to_max or c.low >= 0:
        return c.low, c.high
    faces = _remapped(c, n)
    return min(faces), max(faces)
