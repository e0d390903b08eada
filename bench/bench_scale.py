"""How `modelkit validate` scales with model size and mesh size, `tree` against `check_urdf` on a
1000-link chain, and files per second over the corpus with `validate -j 1` and `-j 2`.

    python bench/bench_scale.py [--repeat N] [--corpus DIR] [--json FILE] [--max-links N]

Inputs, generated in a temporary folder:

- serial chains of 10, 100, 1,000 and 10,000 links as URDF, Choreonoid `.body` and SDF (every
  link with an inertial, a box visual and a cylinder collision);
- binary STL meshes of 10^3 .. 10^6 triangles, each referenced by a one-link URDF (as visual
  and collision).

For each input: `validate` in this process (``modelkit.api.validate``, after one warm-up run;
median of ``--repeat`` runs, fewer for the largest inputs), and one fresh `modelkit validate`
process. The time per link (per triangle) is printed beside it: a flat column is a linear check.

`tree` on the 1000-link URDF chain: fresh processes taking turns, `check_urdf`, `python -c pass`,
`python -c "import modelkit.cli"` and `modelkit tree`, 10 runs each, medians and ratios.

A benchmark reports, it never fails: exit 0 whatever the figures.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from bench_tree import chain_urdf
from bench_validate import REPO, cached_bytecode_env, cpu_model, modelkit_command, timed_many

DEFAULT_CORPUS = REPO.parent / "shared" / "corpus"
SIZES = (10, 100, 1000, 10_000)
TRIANGLES = (10**3, 10**4, 10**5, 10**6)


def chain_body(links: int) -> str:
    """The same chain as `chain_urdf`, as a Choreonoid `.body` file."""
    out = ["format: ChoreonoidBody", "format_version: 2.0", "angle_unit: degree", "name: chain",
           "root_link: link0", "links:"]
    for i in range(links):
        out.append(f"  - name: link{i}")
        if i:
            out += [f"    parent: link{i - 1}", "    joint_type: revolute",
                    f"    joint_id: {i - 1}", "    joint_axis: [0, 1, 0]", "    translation: [0, 0, 0.1]",
                    "    rotation: [0, 0, 1, 5.73]"]
            if i % 2:
                out.append("    joint_range: [-86, 86]")
        else:
            out.append("    joint_type: free")
        out += ["    center_of_mass: [0, 0, 0.05]", "    mass: 0.5",
                "    inertia: [0.001, 0, 0, 0, 0.001, 0, 0, 0, 0.0005]", "    elements:",
                "      - type: Visual", "        elements:",
                "          - type: Shape", "            geometry: { type: Box, size: [0.05, 0.05, 0.1] }",
                "      - type: Collision", "        elements:",
                "          - type: Shape",
                "            geometry: { type: Cylinder, radius: 0.03, height: 0.1 }"]
    return "\n".join(out) + "\n"


def big_body(target_bytes: int = 50_000_000, grid: int = 140) -> str:
    """A real-looking large `.body`: a chain of links, each drawn by an inline `TriangleMesh` (a torus of
    ``grid``² vertices, as Choreonoid's scene writer exports converted meshes: flow lists over many lines),
    with a primitive collision, an inertial and a joint; links are added until ``target_bytes`` is reached.
    Every list stays under the default `--max-list-items` (250,000)."""
    head = ["format: ChoreonoidBody", "format_version: 2.0", "angle_unit: degree", "name: big",
            "root_link: link0", "links:"]
    vertices: list[str] = []
    for i in range(grid):
        u = 2 * math.pi * i / grid
        for j in range(grid):
            w = 2 * math.pi * j / grid
            r = 0.1 + 0.03 * math.cos(w)
            vertices.append(f"{r * math.cos(u):.6f}, {r * math.sin(u):.6f}, {0.03 * math.sin(w):.6f}")
    triangles: list[str] = []
    for i in range(grid):
        for j in range(grid):
            a, b = i * grid + j, ((i + 1) % grid) * grid + j
            c, d = ((i + 1) % grid) * grid + (j + 1) % grid, i * grid + (j + 1) % grid
            triangles.append(f"{a}, {b}, {c}, {a}, {c}, {d}")
    pad = "                  "
    vertex_text = ",\n".join(pad + ", ".join(vertices[k:k + 4]) for k in range(0, len(vertices), 4))
    triangle_text = ",\n".join(pad + ", ".join(triangles[k:k + 3]) for k in range(0, len(triangles), 3))
    out = "\n".join(head) + "\n"
    i = 0
    while len(out) < target_bytes:
        link = [f"  - name: link{i}"]
        if i:
            link += [f"    parent: link{i - 1}", "    joint_type: revolute", f"    joint_id: {i - 1}",
                     "    joint_axis: [0, 0, 1]", "    translation: [0, 0, 0.1]",
                     "    joint_range: [-170, 170]"]
        else:
            link.append("    joint_type: free")
        link += ["    center_of_mass: [0, 0, 0]", "    mass: 0.5",
                 "    inertia: [0.0025, 0, 0, 0, 0.0025, 0, 0, 0, 0.005]", "    elements:",
                 "      - type: Visual", "        elements:", "          - type: Shape",
                 "            appearance: { material: { diffuse: [0.6, 0.6, 0.7] } }",
                 "            geometry:", "              type: TriangleMesh", "              vertices: [",
                 vertex_text + " ]", "              faces: [", triangle_text + " ]",
                 "      - type: Collision", "        elements:", "          - type: Shape",
                 "            geometry: { type: Cylinder, radius: 0.13, height: 0.06 }"]
        out += "\n".join(link) + "\n"
        i += 1
    return out


def chain_sdf(links: int) -> str:
    """The same chain as `chain_urdf`, as SDF 1.9 (poses relative to the parent link)."""
    out = ['<?xml version="1.0"?>', '<sdf version="1.9">', '<model name="chain">']
    for i in range(links):
        pose = f'<pose relative_to="link{i - 1}">0 0 0.1 0 0 0.1</pose>' if i else ""
        out.append(
            f'  <link name="link{i}">{pose}<inertial><pose>0 0 0.05 0 0 0</pose><mass>0.5</mass>'
            "<inertia><ixx>0.001</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.001</iyy><iyz>0</iyz>"
            "<izz>0.0005</izz></inertia></inertial>"
            '<visual name="v"><geometry><box><size>0.05 0.05 0.1</size></box></geometry></visual>'
            '<collision name="c"><geometry><cylinder><radius>0.03</radius><length>0.1</length></cylinder>'
            "</geometry></collision></link>"
        )
        if i:
            kind = "revolute"
            limit = "<limit><lower>-1.5</lower><upper>1.5</upper></limit>" if i % 2 else ""
            out.append(
                f'  <joint name="joint{i:05d}" type="{kind}"><parent>link{i - 1}</parent>'
                f"<child>link{i}</child><axis><xyz>0 1 0</xyz>{limit}</axis></joint>"
            )
    out += ["</model>", "</sdf>"]
    return "\n".join(out) + "\n"


def stl_mesh(path: Path, triangles: int) -> None:
    """A closed-looking binary STL: a tessellated sphere-ish strip of ``triangles`` triangles."""
    rows = max(1, int(math.sqrt(triangles / 2)))
    cols = max(1, triangles // (2 * rows))
    def vertex(r: int, c: int) -> tuple[float, float, float]:
        theta = math.pi * r / rows
        phi = 2 * math.pi * c / cols
        return (0.05 * math.sin(theta) * math.cos(phi), 0.05 * math.sin(theta) * math.sin(phi),
                0.05 * math.cos(theta))
    tri = struct.Struct("<12fH")
    data = bytearray(b"modelkit bench".ljust(80, b" "))
    data += struct.pack("<I", triangles)
    count = 0
    while count < triangles:
        for r in range(rows):
            for c in range(cols):
                a, b, cc, d = vertex(r, c), vertex(r + 1, c), vertex(r + 1, c + 1), vertex(r, c + 1)
                for t in ((a, b, cc), (a, cc, d)):
                    if count < triangles:
                        data += tri.pack(0.0, 0.0, 0.0, *t[0], *t[1], *t[2], 0)
                        count += 1
    path.write_bytes(bytes(data))


def mesh_urdf(mesh: str) -> str:
    return (
        '<?xml version="1.0"?>\n<robot name="meshy">\n  <link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
        f'<visual><geometry><mesh filename="{mesh}"/></geometry></visual>'
        f'<collision><geometry><mesh filename="{mesh}"/></geometry></collision></link>\n</robot>\n'
    )


def in_process(path: Path, repeat: int) -> dict[str, Any]:
    """Median wall time of ``modelkit.api.validate`` on ``path`` after one warm-up run."""
    from modelkit.api import validate
    from modelkit.geometry import meshfiles

    clear = getattr(meshfiles, "clear_mesh_cache", lambda: None)  # time the mesh load on every run
    first = validate(path)  # warm-up: imports
    walls = []
    for _ in range(repeat):
        clear()
        start = time.perf_counter()
        validate(path)
        walls.append(time.perf_counter() - start)
    codes = sorted({d.code for d in first.diagnostics})
    return {"runs": repeat, "median_s": statistics.median(walls), "min_s": min(walls), "codes": codes}


def fresh(command: list[str], env: dict[str, str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, capture_output=True, check=False, env=env)
    return time.perf_counter() - start


def fresh_with_rss(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall time (s) and peak resident memory (MiB) of one fresh process."""
    probe = ("import resource, subprocess, sys; subprocess.run(sys.argv[1:], capture_output=True); "
             "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", probe, *command], capture_output=True, text=True, env=env,
                          check=False)
    return time.perf_counter() - start, int(done.stdout.strip() or 0) / 1024


def repeat_for(size: int, repeat: int, big: int) -> int:
    return repeat if size < big else max(1, repeat // 3)


def corpus_files(corpus: Path) -> list[str]:
    return sorted(str(p) for ext in ("body", "urdf", "sdf") for p in corpus.rglob(f"*.{ext}"))


def throughput(mk: list[str], files: list[str], jobs: int, env: dict[str, str], runs: int) -> dict[str, Any]:
    command = [*mk, "validate", "-j", str(jobs), *files]
    fresh(command, env)  # warm-up
    walls = [fresh(command, env) for _ in range(runs)]
    median = statistics.median(walls)
    return {"jobs": jobs, "files": len(files), "runs": runs, "median_s": median,
            "files_per_s": len(files) / median if median else None}


def run(repeat: int, corpus: Path, max_links: int, work: Path, env: dict[str, str]) -> dict[str, Any]:
    mk = modelkit_command()
    results: dict[str, Any] = {"chains": {}, "meshes": {}}
    writers = {"urdf": chain_urdf, "body": chain_body, "sdf": chain_sdf}
    for fmt, write in writers.items():
        rows = []
        warm = work / f"warm.{fmt}"
        warm.write_text(write(2))
        fresh([*mk, "validate", str(warm)], env)  # bytecode cache for this format's modules
        for size in (s for s in SIZES if s <= max_links):
            path = work / f"chain{size}.{fmt}"
            path.write_text(write(size))
            row = {"links": size, "bytes": path.stat().st_size,
                   "in_process": in_process(path, repeat_for(size, repeat, 10_000)),
                   "fresh_s": fresh([*mk, "validate", str(path)], env)}
            row["in_process_per_link_us"] = row["in_process"]["median_s"] / size * 1e6
            rows.append(row)
            print(f"  {fmt:4} {size:>6} links  {row['in_process']['median_s'] * 1e3:9.1f} ms in-process "
                  f"({row['in_process_per_link_us']:7.1f} µs/link)  fresh {row['fresh_s'] * 1e3:8.1f} ms  "
                  f"{','.join(row['in_process']['codes']) or 'clean'}", flush=True)
        results["chains"][fmt] = rows
    # issue 9 §2: a 10,000-link .body and a 50 MB real-looking .body, < 20 s and < 1 GiB each
    big = work / "big50.body"
    big.write_text(big_body())
    results["large_body"] = []
    for path in (work / "chain10000.body", big):
        if path.exists():
            wall, rss = fresh_with_rss([*mk, "validate", str(path)], env)
            results["large_body"].append({"file": path.name, "bytes": path.stat().st_size, "fresh_s": wall,
                                          "peak_rss_mib": rss})
            print(f"  {path.name}: {path.stat().st_size / 1e6:.1f} MB, fresh validate {wall:.2f} s, "
                  f"peak RSS {rss:.0f} MiB", flush=True)
    rows = []
    for tris in TRIANGLES:
        mesh = work / f"mesh{tris}.stl"
        stl_mesh(mesh, tris)
        urdf = work / f"mesh{tris}.urdf"
        urdf.write_text(mesh_urdf(mesh.name))
        if tris == TRIANGLES[0]:
            fresh([*mk, "validate", str(urdf)], env)  # bytecode cache for the mesh modules
        row = {"triangles": tris, "stl_bytes": mesh.stat().st_size,
               "in_process": in_process(urdf, repeat_for(tris, repeat, 10**6)),
               "fresh_s": fresh([*mk, "validate", str(urdf)], env)}
        row["in_process_per_triangle_ns"] = row["in_process"]["median_s"] / tris * 1e9
        rows.append(row)
        print(f"  stl  {tris:>8} tris  {row['in_process']['median_s'] * 1e3:9.1f} ms in-process "
              f"({row['in_process_per_triangle_ns']:7.0f} ns/tri)  fresh {row['fresh_s'] * 1e3:8.1f} ms  "
              f"{','.join(row['in_process']['codes']) or 'clean'}", flush=True)
    results["meshes"] = rows

    check_urdf = shutil.which("check_urdf")
    chain = work / "chain1000.urdf"
    if not chain.exists():
        chain.write_text(chain_urdf(1000))
    jobs: dict[str, Any] = {
        "python -c pass": ([sys.executable, "-c", "pass"], env),
        "import modelkit.cli": ([sys.executable, "-c", "import modelkit.cli"], env),
        "modelkit tree": ([*mk, "tree", str(chain)], env),
    }
    if check_urdf:
        jobs["check_urdf"] = ([check_urdf, str(chain)], env)
    tree = timed_many(jobs, 10)
    med = {name: stats["median_s"] for name, stats in tree.items()}
    split = {"interpreter_s": med["python -c pass"],
             "import_s": med["import modelkit.cli"] - med["python -c pass"],
             "work_s": med["modelkit tree"] - med["import modelkit.cli"]}
    ratio = med["modelkit tree"] / med["check_urdf"] if check_urdf else None
    results["tree_1000"] = {"timings": tree, "split": split, "ratio_to_check_urdf": ratio}
    print(f"  tree 1000 links: modelkit {med['modelkit tree'] * 1e3:.0f} ms, "
          + (f"check_urdf {med['check_urdf'] * 1e3:.0f} ms, ratio "
             f"{results['tree_1000']['ratio_to_check_urdf']:.1f}x; " if check_urdf else "")
          + "split: " + ", ".join(f"{k} {v * 1e3:.0f} ms" for k, v in split.items()), flush=True)

    files = corpus_files(corpus) if corpus.is_dir() else []
    runs = max(3, repeat)
    results["corpus_throughput"] = [throughput(mk, files, j, env, runs) for j in (1, 2)] if files else []
    # the corpus four times over: a longer run, where the workers' start-up and imports weigh less
    results["corpus_throughput"] += [throughput(mk, files * 4, j, env, runs) for j in (1, 2)] if files else []
    for row in results["corpus_throughput"]:
        print(f"  corpus -j {row['jobs']}: {row['files']} files in {row['median_s']:.2f} s "
              f"-> {row['files_per_s']:.1f} files/s", flush=True)
    return results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS)
    parser.add_argument("--max-links", type=int, default=10_000)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="mk-scale-") as tmp:
        work = Path(tmp) / "models"
        work.mkdir()
        env = cached_bytecode_env(Path(tmp) / "pycache")
        results = run(args.repeat, args.corpus, args.max_links, work, env)
    results["machine"] = {"cpu": cpu_model(), "python": platform.python_version(),
                          "when": datetime.now(UTC).isoformat(timespec="seconds")}
    if args.json:
        args.json.write_text(json.dumps(results, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
