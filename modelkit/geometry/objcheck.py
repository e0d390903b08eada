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

Whatever it cannot decide exactly and cheaply (a number numpy and Python might read differently, an
unusual white-space character, a face token that is not ``a``, ``a/b``, ``a//c`` or ``a/b/c`` with plain
integers, an error whose text comes from numpy) gives :data:`UNDECIDED`: the caller then loads the file.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from itertools import pairwise

__all__ = ["UNDECIDED", "obj_problem"]

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
# face lines made only of these characters: integers, slashes, blanks
_NOT_FACE_CHAR = re.compile(r"[^0-9/\- \t]")
# numpy's message when np.fromstring meets something that is not a number
_NUMPY_UNMATCHED = "string or file could not be read to its end due to unmatched data"
_INT_LIMIT = 2**62  # larger indices: numpy's int64 reading might wrap or saturate


class _Undecided(Exception):
    """The fast check cannot decide exactly: load the file."""


class _Malformed(Exception):
    """A ``v``/``vt``/``vn`` row holds something that is not a number (numpy's reader refuses it)."""


@dataclass
class _Vertices:
    rows: int  # rows of trimesh's vertex array
    columns: int  # its columns after trimesh keeps at most three
    first_bad_row: int | None  # first row with a NaN/infinite coordinate among those columns


@dataclass
class _Chunk:
    faces: list[int]  # vertex indices, row-major, ``width`` per face (trimesh's 0-based, negatives kept)
    width: int  # vertices per face
    masked_to_max: bool  # the vertex mask is arange(max + 1) (texture or normal indices present)


def obj_problem(data: bytes, name: str) -> str | None:
    """None when ``load_mesh`` loads an OBJ file with these bytes (no fragment, no metadata), else
    ``"MK501\\t<message>"`` with the message of its :class:`MeshLoadError`, or :data:`UNDECIDED`."""
    if not data.strip():
        return f"MK501\t{name} is empty"
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    if "\x00" in text:
        return f"MK501\t{name} contains NUL bytes: not a text OBJ file"
    # trimesh: leading/trailing newline, \r\n -> \n, backslash continuations merged
    text = "\n{}\n".format(text.strip().replace("\r\n", "\n")).replace("\\\n", "")
    if _ODD_SPACE.search(text):
        return UNDECIDED
    try:
        verts, has_normals = _vertices(text)
        if verts is None:  # trimesh returns no geometry
            return f"MK501\t{name} contains no faces: not a usable OBJ file"
        chunks = [_chunk(c, has_normals) for c in _face_chunks(text)]
        return _verdict(verts, chunks, name)
    except _Malformed:
        return f"MK501\t{name}: malformed OBJ ({_NUMPY_UNMATCHED})"
    except _Undecided:
        return UNDECIDED


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
    verts: _Vertices | None = None
    for k, s in starts.items():
        if s < 0:
            continue
        rows = [i.split("\n", 1)[0] for i in chunk.split(f"\n{k} ")[1:]]
        if not rows:
            raise _Undecided
        table = _number_rows(rows)
        if k == "v":
            verts = table
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
    per_row = len(rows[0].split())
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


def _ints(text: str) -> list[int]:
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
    face_lines = [i.split("\n", 1)[0].strip() for i in re.split("^f", chunk, flags=re.MULTILINE)[1:]]
    if _NOT_FACE_CHAR.search(" ".join(face_lines)):
        raise _Undecided
    columns = [len(f.replace("/", " ").split()) for f in face_lines]
    if all(c == columns[0] for c in columns):
        return _vectorised(face_lines, columns[0], has_normals)
    return _per_line(face_lines, has_normals)


def _vectorised(face_lines: list[str], columns: int, has_normals: bool) -> _Chunk:
    sample = face_lines[0]
    values = _ints(" ".join(face_lines).replace("/", " "))
    group_count = len(sample.strip().split())
    if columns == 0 or group_count == 0 or columns % group_count:
        raise _Undecided  # numpy errors or trimesh's slicing of mixed token forms
    per_ref = columns // group_count
    faces = [x - 1 if x > 0 else x for x in values[::per_ref]]
    tex = norm = False
    if per_ref == 2:
        count = "".join(i.strip("/") for i in sample.split()).count("/")
        if count == columns:  # a//c
            norm = True
        elif count == columns // 2:  # a/b
            tex = True
    elif per_ref == 3:  # a/b/c
        tex = norm = True
    return _Chunk(faces, group_count, tex or (norm and has_normals))


def _per_line(face_lines: list[str], has_normals: bool) -> _Chunk:
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
            parts = token.split("/")
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
    return _Chunk([x - 1 if x > 0 else x for x in v], 3, tex or (norm and has_normals))


def _is_int(token: str) -> bool:
    try:
        int(token)
    except ValueError:
        return False
    return True


# ---- the checks of load_obj, _load_obj and _finish, in their order ---------------------------------


def _verdict(verts: _Vertices, chunks: list[_Chunk], name: str) -> str | None:
    if not chunks:  # trimesh returns a point cloud
        return f"MK501\t{name} contains no faces: not a usable OBJ file"
    n = verts.rows
    used_rows: list[int] = []  # vertex rows each chunk keeps
    for c in chunks:
        lo, hi = min(c.faces), max(c.faces)
        if c.masked_to_max:  # unmerge_faces(maintain_faces=True): mask arange(max + 1)
            if hi < -1:
                raise _Undecided  # numpy: negative dimensions
            first3 = [x for i, x in enumerate(c.faces) if i % c.width < 3] if c.width > 3 else c.faces
            if min(first3) < -(hi + 1) or hi + 1 > n:
                return f"MK501\t{name}: a face refers to a vertex that does not exist"
            used_rows.append(hi + 1)
        else:  # mask of all vertices; indices remapped into [0, n)
            if lo < -n or hi > n - 1:
                return f"MK501\t{name}: a face refers to a vertex that does not exist"
            used_rows.append(n)
    # meshfiles._load_obj: trimesh's chunks come out in reverse order; each is reshaped to (-1, 3)
    pieces = list(reversed(list(zip(chunks, used_rows, strict=True))))
    sizes = []
    for _, rows in pieces:
        size = rows * verts.columns
        if size % 3:
            return (f"MK501\tcannot load {name}: ValueError: "
                    f"cannot reshape array of size {size} into shape (3)")
        sizes.append(size // 3)
    total = sum(sizes)
    offset = 0
    n_triangles = 0
    out_of_range = False
    for (c, _), nv in zip(pieces, sizes, strict=True):
        faces = c.faces if c.masked_to_max else [x + n if x < 0 else x for x in c.faces]
        if c.width == 3:
            n_triangles += len(faces) // 3
            if min(faces) < 0 or max(faces) + offset >= total:
                out_of_range = True
        elif c.width > 3:  # polygons with an index outside the vertices are skipped
            w = c.width
            kept = sum(1 for i in range(0, len(faces), w) if all(0 <= x < nv for x in faces[i : i + w]))
            n_triangles += kept * (w - 2)
        offset += nv
    if out_of_range:
        return f"MK501\t{name}: face index out of range"
    if n_triangles == 0:
        return f"MK501\t{name} contains no triangles"
    if verts.first_bad_row is not None and verts.first_bad_row < max(used_rows):
        return f"MK501\t{name} has non-finite vertex coordinates (NaN or infinity)"
    return None
