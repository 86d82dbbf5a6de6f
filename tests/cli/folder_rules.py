#!/usr/bin/env python3
"""folder_rules.py ROOT: the repository's folder rules, checked on its #include lines and on the
target_link_libraries lines of its CMakeLists.txt files.

1. Which folder may include which. The arrows between the library folders, from their
   `#include "folder/..."` lines (a file including a header of another folder):
       io -> sim
       model -> sim, io
       diagnosis -> model, io, sim
       compensation -> model, io, sim
       validation -> compensation, model, io, sim
       tools, python -> any of them
   Any other arrow fails, and so does a cycle (python -> tools and tools -> python, say).
   The same arrows hold for the link lines: a target of a folder's CMakeLists.txt may link the
   library of another folder (rlg_io, the add_library of io/CMakeLists.txt) only along an arrow,
   and the folders a folder's targets link are exactly those it includes: a link to a folder
   whose headers it never includes is a dependency the code does not have (it goes on linking
   through the libraries that need it), and an include of a folder it does not link leans on
   another library's link line.
2. Where the heavy third-party libraries may be included, anywhere in the repository:
       Ceres (<ceres/...>)                                  only in diagnosis/
       SUNDIALS (<sundials/...>, <cvodes/...>, <nvector/...>,
                 <sunlinsol/...>, <sunmatrix/...>)          only in one file, in sim/
       TBB (<tbb/...>, <oneapi/...>)                        only in validation/
       PLplot (<plplot/...>)                                only in tools/rlgtherm/plot_kit.cpp
                                                            and tools/rlgtherm/verb_figures.cpp
   and the same for their link targets (Ceres::, SUNDIALS::, TBB::, PkgConfig::PLPLOT) in any
   CMakeLists.txt: only diagnosis/, sim/, validation/ and tools/ link them,
   so that a change of one of them touches one folder, and a library that does not need one
   does not link it.
3. A folder with rooms shows a small face: other folders include only the headers at its top,
   never one in a subfolder (FACES: diagnosis/, whose top holds what callers use and whose
   subfolders hold its pipelines). Tests may include anything.
Prints the folder graphs it found (includes, links); on a broken rule, each offending #include
or link line (file:line) and the rule, and exits 1. `folder_rules.py --self-test` checks that a tree breaking each rule
fails and one keeping them passes.
"""
import io
import os
import re
import subprocess
import sys
import tempfile

FOLDERS = ["sim", "io", "model", "diagnosis", "compensation", "validation", "tools", "python"]
ALLOWED = {
    "sim": set(),
    "io": {"sim"},
    "model": {"sim", "io"},
    "diagnosis": {"model", "io", "sim"},
    "compensation": {"model", "io", "sim"},
    "validation": {"compensation", "model", "io", "sim"},
    "tools": set(FOLDERS) - {"tools"},
    "python": set(FOLDERS) - {"python"},
}
SOURCE = re.compile(r"\.(h|hh|hpp|hxx|c|cc|cpp|cxx|inl|ipp)$")
LOCAL_INCLUDE = re.compile(r'^\s*#\s*include\s*"([A-Za-z0-9_]+)/')
# Folders whose subfolders are their own business: others include only the headers at the top.
FACES = {"diagnosis"}
FACE_INCLUDE = re.compile(r'^\s*#\s*include\s*"([A-Za-z0-9_]+)/([^"]+)"')
SYSTEM_INCLUDE = re.compile(r"^\s*#\s*include\s*<([A-Za-z0-9_]+)/")
# Third-party libraries: the first directory of their headers, and where they may be included.
LIBRARIES = [
    ("Ceres", {"ceres"}, lambda path: path.startswith("diagnosis/"), "only in diagnosis/", False),
    ("SUNDIALS", {"sundials", "cvodes", "nvector", "sunlinsol", "sunmatrix"},
     lambda path: path.startswith("sim/"), "only in one file, in sim/", True),
    ("TBB", {"tbb", "oneapi"}, lambda path: path.startswith("validation/"), "only in validation/", False),
    ("PLplot", {"plplot"},
     lambda path: path in ("tools/rlgtherm/plot_kit.cpp", "tools/rlgtherm/verb_figures.cpp"),
     "only in tools/rlgtherm/plot_kit.cpp and tools/rlgtherm/verb_figures.cpp", False),
]
# Their CMake targets, and the one CMakeLists.txt that may link each (the folder that includes it).
LINKED_LIBRARIES = [
    ("Ceres", re.compile(r"^Ceres::"), "diagnosis/CMakeLists.txt"),
    ("SUNDIALS", re.compile(r"^SUNDIALS::"), "sim/CMakeLists.txt"),
    ("TBB", re.compile(r"^TBB::"), "validation/CMakeLists.txt"),
    ("PLplot", re.compile(r"^PkgConfig::PLPLOT$"), "tools/CMakeLists.txt"),
]
CMAKE_CALL = re.compile(r"\b(add_library|target_link_libraries)\s*\(([^()]*)\)", re.S)


def repository_files(root):
    """The repository's files, relative to root: git's list, or a walk without builds."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True, check=True).stdout
        files = [f for f in out.decode().split("\0") if f]
    except (OSError, subprocess.CalledProcessError):
        files = []
        for d, dirs, names in os.walk(root):
            dirs[:] = [x for x in dirs if x != ".git" and not x.startswith("build")]
            files += [os.path.relpath(os.path.join(d, n), root) for n in names]
    return sorted(f for f in files if os.path.isfile(os.path.join(root, f)))


def source_files(root):
    """The repository's C and C++ files."""
    return [f for f in repository_files(root) if SOURCE.search(f)]


def cmake_files(root):
    """The repository's CMakeLists.txt files."""
    return [f for f in repository_files(root) if os.path.basename(f) == "CMakeLists.txt"]


def cmake_calls(root, path):
    """(command, [words], line) of every add_library and target_link_libraries call in a file."""
    with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
        text = "".join(re.sub(r"#.*", "", line) for line in f)  # comments out, lines kept
    return [(m.group(1), m.group(2).split(), text.count("\n", 0, m.start()) + 1)
            for m in CMAKE_CALL.finditer(text)]


def link_lines(root):
    """Link arrows between folders, {(from, to): [file:line, ...]}, and the third-party link
    targets, [(CMakeLists.txt, line, target)]: from every target_link_libraries call, a word
    naming a library that another folder's CMakeLists.txt adds (add_library) is an arrow."""
    files = cmake_files(root)
    owner = {}  # library target -> its folder
    calls = {path: cmake_calls(root, path) for path in files}
    for path, found in calls.items():
        folder = path.split("/", 1)[0] if "/" in path else ""
        for command, words, _ in found:
            if command == "add_library" and words and folder in FOLDERS:
                owner[words[0]] = folder
    arrows, third_party = {}, []
    for path, found in calls.items():
        folder = path.split("/", 1)[0] if "/" in path else ""
        for command, words, number in found:
            if command != "target_link_libraries":
                continue
            for word in words[1:]:
                to = owner.get(word)
                if folder in FOLDERS and to and to != folder:
                    arrows.setdefault((folder, to), []).append(f"{path}:{number} ({word})")
                if any(pattern.search(word) for _, pattern, _ in LINKED_LIBRARIES):
                    third_party.append((path, number, word))
    return arrows, third_party


def find_cycles(edges):
    """Every elementary cycle's nodes, each cycle once (the graph has eight nodes)."""
    cycles = []
    def walk(start, node, path):
        for nxt in sorted(edges.get(node, ())):
            if nxt == start:
                cycles.append(path[:])
            elif nxt not in path and FOLDERS.index(nxt) > FOLDERS.index(start):
                walk(start, nxt, path + [nxt])
    for start in FOLDERS:
        walk(start, start, [start])
    return cycles


def check(root, out=sys.stdout):
    """Prints the graph and every broken rule; returns the number of broken rules."""
    arrows = {}  # (from, to) -> [file:line, ...]
    library_uses = {name: [] for name, *_ in LIBRARIES}
    behind_face = []  # includes of a header inside a FACES folder's subfolder, from outside it
    for path in source_files(root):
        folder = path.split("/", 1)[0]
        with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
            for number, line in enumerate(f, 1):
                m = LOCAL_INCLUDE.match(line)
                if m and folder in FOLDERS and m.group(1) in FOLDERS and m.group(1) != folder:
                    arrows.setdefault((folder, m.group(1)), []).append(f"{path}:{number}")
                m = FACE_INCLUDE.match(line)
                if m and m.group(1) in FACES and folder != m.group(1) and folder != "tests" and "/" in m.group(2):
                    behind_face.append(f"{path}:{number}: {line.strip()}")
                m = SYSTEM_INCLUDE.match(line)
                if m:
                    for name, dirs, *_ in LIBRARIES:
                        if m.group(1) in dirs:
                            library_uses[name].append((path, number, line.strip()))
    print("folder graph (#include \"folder/...\" lines from one folder to another):", file=out)
    for src in FOLDERS:
        targets = sorted((to for (frm, to) in arrows if frm == src), key=FOLDERS.index)
        shown = ", ".join(f"{to} ({len(arrows[(src, to)])})" for to in targets) or "(none)"
        print(f"  {src:12} -> {shown}", file=out)
    broken = 0
    for (src, to), where in sorted(arrows.items()):
        if to not in ALLOWED[src]:
            broken += 1
            allowed = ", ".join(sorted(ALLOWED[src], key=FOLDERS.index)) or "no other folder"
            print(f"FOLDER RULE BROKEN: {src}/ includes {to}/ ({len(where)} line(s)); {src}/ may include "
                  f"{allowed}:", file=out)
            for w in where:
                print(f"  {w}", file=out)
    edges = {}
    for src, to in arrows:
        edges.setdefault(src, set()).add(to)
    for cycle in find_cycles(edges):
        broken += 1
        ring = cycle + [cycle[0]]
        print("FOLDER RULE BROKEN: include cycle " + " -> ".join(ring) + ":", file=out)
        for a, b in zip(ring, ring[1:]):
            print(f"  {a} -> {b}: {arrows[(a, b)][0]}" + (f" (and {len(arrows[(a, b)]) - 1} more)"
                                                         if len(arrows[(a, b)]) > 1 else ""), file=out)
    for name, _, allowed_at, rule, one_file in LIBRARIES:
        uses = library_uses[name]
        files = sorted({p for p, _, _ in uses})
        wrong = [u for u in uses if not allowed_at(u[0])]
        if wrong or (one_file and len(files) > 1):
            broken += 1
            print(f"LIBRARY RULE BROKEN: {name} may be included {rule}; it is included in:", file=out)
            for p, number, line in uses:
                print(f"  {p}:{number}: {line}", file=out)
        else:
            print(f"{name}: included in {', '.join(files) or 'no file'} ({rule})", file=out)
    if behind_face:
        broken += 1
        print(f"FACE RULE BROKEN: outside {', '.join(sorted(FACES))}/ only the headers at its top may be "
              "included:", file=out)
        for w in behind_face:
            print(f"  {w}", file=out)
    return broken + check_links(root, arrows, out)


def check_links(root, include_arrows, out):
    """Prints the link graph and every broken link rule; returns the number broken."""
    arrows, third_party = link_lines(root)
    print("link graph (target_link_libraries of a folder's CMakeLists.txt naming another folder's library):",
          file=out)
    for src in FOLDERS:
        targets = sorted((to for (frm, to) in arrows if frm == src), key=FOLDERS.index)
        print(f"  {src:12} -> {', '.join(targets) or '(none)'}", file=out)
    broken = 0
    for (src, to), where in sorted(arrows.items()):
        if to not in ALLOWED[src]:
            broken += 1
            print(f"LINK RULE BROKEN: {src}/ links {to}/'s library; {src}/ may use "
                  f"{', '.join(sorted(ALLOWED[src], key=FOLDERS.index)) or 'no other folder'}:", file=out)
            for w in where:
                print(f"  {w}", file=out)
        elif (src, to) not in include_arrows:
            broken += 1
            print(f"LINK RULE BROKEN: {src}/ links {to}/'s library but includes nothing of {to}/:", file=out)
            for w in where:
                print(f"  {w}", file=out)
    for (src, to), where in sorted(include_arrows.items()):
        if to in ALLOWED[src] and (src, to) not in arrows:
            broken += 1
            print(f"LINK RULE BROKEN: {src}/ includes {to}/ ({len(where)} line(s), first {where[0]}) but no "
                  f"target of {src}/CMakeLists.txt links {to}/'s library", file=out)
    for name, pattern, allowed in LINKED_LIBRARIES:
        uses = [u for u in third_party if pattern.search(u[2])]
        wrong = [u for u in uses if u[0] != allowed]
        if wrong:
            broken += 1
            print(f"LINK RULE BROKEN: {name} may be linked only in {allowed}; it is linked in:", file=out)
            for p, number, word in wrong:
                print(f"  {p}:{number}: {word}", file=out)
        else:
            print(f"{name}: linked in {', '.join(sorted({u[0] for u in uses})) or 'no file'} (only in {allowed})",
                  file=out)
    return broken


def self_test():
    """A tree keeping the rules passes; each tree breaking one fails, naming the rule."""
    good = {
        "sim/a.cpp": "#include <cvodes/cvodes.h>\n#include <sundials/sundials_context.h>\n",
        "io/a.h": '#include "sim/a.h"\n',
        "model/a.h": '#include "sim/a.h"\n#include "io/a.h"\n',
        "diagnosis/a.cpp": '#include <ceres/ceres.h>\n#include "model/a.h"\n',
        "validation/a.cpp": '#include <tbb/task_arena.h>\n#include "compensation/a.h"\n',
        "tools/rlgtherm/plot_kit.cpp": "#include <plplot/plstream.h>\n",
        "python/a.cpp": '#include "tools/rlgtherm/common.h"\n',
        "tests/a.cpp": '#include "tools/a.h"\n',
        # Link lines agreeing with the includes; a commented-out link is no link.
        "sim/CMakeLists.txt": "add_library(rlg_sim a.cpp)\n# target_link_libraries(rlg_sim rlg_io)\n"
                              "target_link_libraries(rlg_sim PRIVATE SUNDIALS::cvodes)\n",
        "io/CMakeLists.txt": "add_library(rlg_io a.cpp)\ntarget_link_libraries(rlg_io PUBLIC rlg_sim)\n",
        "model/CMakeLists.txt": "add_library(rlg_model a.cpp)\ntarget_link_libraries(rlg_model\n  PUBLIC rlg_sim rlg_io)\n",
        "diagnosis/CMakeLists.txt": "add_library(rlg_diagnosis a.cpp)\n"
                                    "target_link_libraries(rlg_diagnosis PUBLIC rlg_model PRIVATE Ceres::ceres)\n",
        "compensation/CMakeLists.txt": "add_library(rlg_compensation a.cpp)\n",
        "validation/CMakeLists.txt": "add_library(rlg_validation a.cpp)\n"
                                     "target_link_libraries(rlg_validation PUBLIC rlg_compensation PRIVATE TBB::tbb)\n",
        "tools/CMakeLists.txt": "add_library(rlg_cli rlgtherm/plot_kit.cpp)\n"
                                "target_link_libraries(rlg_cli PRIVATE PkgConfig::PLPLOT)\n",
        "python/CMakeLists.txt": "target_link_libraries(rlgtherm_python PRIVATE rlg_cli)\n",
    }
    bad = {
        "sim includes io": ({"sim/b.cpp": '#include "io/csv.h"\n'}, "FOLDER RULE BROKEN: sim/ includes io/"),
        "cycle": ({"tools/b.cpp": '#include "python/a.h"\n'}, "include cycle tools -> python -> tools"),
        "ceres": ({"model/b.cpp": "#include <ceres/ceres.h>\n"}, "LIBRARY RULE BROKEN: Ceres"),
        "sundials in two files": ({"sim/b.cpp": "#include <nvector/nvector_serial.h>\n"}, "LIBRARY RULE BROKEN: SUNDIALS"),
        "tbb": ({"tools/b.cpp": "#include <oneapi/tbb.h>\n"}, "LIBRARY RULE BROKEN: TBB"),
        "plplot": ({"tools/rlgtherm/b.cpp": "#  include <plplot/plstream.h>\n"}, "LIBRARY RULE BROKEN: PLplot"),
        "sim links io": ({"sim/CMakeLists.txt": "add_library(rlg_sim a.cpp)\ntarget_link_libraries(rlg_sim PUBLIC rlg_io)\n"},
                         "LINK RULE BROKEN: sim/ links io/'s library; sim/ may use no other folder"),
        "link without include": ({"diagnosis/CMakeLists.txt": "add_library(rlg_diagnosis a.cpp)\n"
                                  "target_link_libraries(rlg_diagnosis PUBLIC rlg_model rlg_io PRIVATE Ceres::ceres)\n"},
                                 "LINK RULE BROKEN: diagnosis/ links io/'s library but includes nothing of io/"),
        "include without link": ({"model/CMakeLists.txt": "add_library(rlg_model a.cpp)\n"
                                  "target_link_libraries(rlg_model PUBLIC rlg_sim)\n"},
                                 "LINK RULE BROKEN: model/ includes io/"),
        "behind a face": ({"tools/b.cpp": '#include "diagnosis/network/problem.h"\n',
                           "tools/CMakeLists.txt": "add_library(rlg_cli rlgtherm/plot_kit.cpp b.cpp)\n"
                                                   "target_link_libraries(rlg_cli PRIVATE PkgConfig::PLPLOT rlg_diagnosis)\n"},
                          "FACE RULE BROKEN: outside diagnosis/ only the headers at its top"),
        "tbb linked": ({"python/CMakeLists.txt": "target_link_libraries(rlgtherm_python PRIVATE rlg_cli TBB::tbb)\n"},
                       "LINK RULE BROKEN: TBB may be linked only in validation/CMakeLists.txt"),
    }
    failures = 0
    for name, (extra, expected) in [("rules kept", ({}, None))] + list(bad.items()):
        with tempfile.TemporaryDirectory() as d:
            for rel, text in {**good, **extra}.items():
                os.makedirs(os.path.dirname(os.path.join(d, rel)), exist_ok=True)
                with open(os.path.join(d, rel), "w") as f:
                    f.write(text)
            buf = io.StringIO()
            n = check(d, buf)
            ok = n == 0 if expected is None else (n > 0 and expected in buf.getvalue())
            print(f"{'ok  ' if ok else 'FAIL'} {name}: {n} rule(s) broken")
            if not ok:
                failures += 1
                print(buf.getvalue())
    return failures


def main():
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(1 if self_test() else 0)
    if len(sys.argv) != 2:
        sys.exit("usage: folder_rules.py ROOT | --self-test")
    broken = check(sys.argv[1])
    if broken:
        print(f"{broken} folder or library rule(s) broken (the rules: tests/cli/folder_rules.py)")
        sys.exit(1)
    print("every folder and library rule holds")


if __name__ == "__main__":
    main()
