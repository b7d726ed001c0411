#!/usr/bin/env python3
"""gen_gl_api.py - writes gpu/gl_api.h from the Khronos registry for the GL
names lpvd uses, and checks that the list of those names has not rotted.

The list (gpu/gl_api.txt) names, one a line, every GL command (glFoo) and
enum (GL_FOO) the C code uses, plus any GL type (GLfoo) it names that no
listed command brings in. The registry is gl.xml from Debian's khronos-api
package. Nothing else is read, so the header is the same on every machine
with the same package.

  gen_gl_api.py --xml gl.xml --list gl_api.txt --out gl_api.h
      Writes the header: the GL types the listed names need, a #define per
      enum, a PFN...PROC typedef per command, LPV_GL_FUNCTIONS(X) (the table
      gpu/gl_loader.c defines and loads) and `#define glFoo lpv_gl_glFoo` per
      command. Fails, naming it, on a name that is not in the registry, that
      is not part of the OpenGL 4.5 core profile (the context lpvd asks for),
      or that is listed twice.

  gen_gl_api.py --list gl_api.txt --check-used SOURCE_DIR
      Fails, naming them, when listed names appear nowhere in the C/C++
      sources under SOURCE_DIR (comments and string literals do not count),
      so the list cannot keep names the code stopped using. The other
      direction needs no script: a command or enum that is used but not
      listed is undeclared, which the compiler rejects.

Only the standard library is used (xml.etree), so any Python 3 runs it.
"""

import argparse
import os
import re
import sys
import xml.etree.ElementTree as ET

CORE_VERSION = (4, 5)
SOURCE_SUFFIXES = (".c", ".h", ".cpp", ".hpp", ".cc")


def read_list(path):
    """Names of the list in file order; '#' starts a comment."""
    names = []
    seen = set()
    with open(path, encoding="utf-8") as f:
        for lineno, line in enumerate(f, 1):
            name = line.split("#", 1)[0].strip()
            if not name:
                continue
            if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
                sys.exit(f"{path}:{lineno}: '{name}' is not a GL name")
            if name in seen:
                sys.exit(f"{path}:{lineno}: {name} is listed twice")
            seen.add(name)
            names.append((name, lineno))
    return names


def text_of(elem, skip_name=False):
    """The C text of a registry element, its child tags dropped (a <name>
    child too when skip_name: what is left of a <proto> is the return type)."""
    parts = [elem.text or ""]
    for child in elem:
        if child.tag == "apientry":
            parts.append("APIENTRY")
        elif not (skip_name and child.tag == "name"):
            parts.append("".join(child.itertext()))
        parts.append(child.tail or "")
    return re.sub(r"\s+", " ", "".join(parts)).strip()


class Registry:
    def __init__(self, path):
        root = ET.parse(path).getroot()
        # Types in registry order, which defines each before its users.
        self.types = []  # (name, C text)
        for t in root.find("types"):
            if t.get("api") not in (None, "gl"):
                continue
            name = t.get("name") or "".join(t.find("name").itertext())
            self.types.append((name, text_of(t)))
        self.type_names = {n for n, _ in self.types}
        # Enum values, the desktop-GL one where GL and GL ES differ.
        self.enums = {}
        for group in root.iter("enums"):
            for e in group.findall("enum"):
                if e.get("api") not in (None, "gl"):
                    continue
                suffix = {"u": "u", "ull": "ull"}.get(e.get("type"), "")
                self.enums[e.get("name")] = e.get("value") + suffix
        self.commands = {}  # name -> (return type, [param C text], [ptype])
        for c in root.find("commands").findall("command"):
            proto = c.find("proto")
            name = "".join(proto.find("name").itertext())
            params = c.findall("param")
            ptypes = [p.text for p in proto.iter("ptype")]
            for p in params:
                ptypes += [pt.text for pt in p.iter("ptype")]
            self.commands[name] = (text_of(proto, skip_name=True), [text_of(p) for p in params], ptypes)
        # The GL 4.5 core profile: what the GL_VERSION_x_y features up to
        # 4.5 require, less what they remove from the core profile (3.2
        # removed the fixed pipeline; 4.3 brought a few names back), and the
        # version that brought each name in.
        self.core = {}
        for f in root.findall("feature"):
            if f.get("api") != "gl":
                continue
            version = tuple(int(x) for x in f.get("number").split("."))
            if version > CORE_VERSION:
                continue
            for block in f:
                if block.get("profile") not in (None, "core"):
                    continue
                for item in block:
                    n = item.get("name")
                    if block.tag == "require":
                        self.core.setdefault(n, version)
                    elif block.tag == "remove":
                        self.core.pop(n, None)


def type_closure(reg, wanted):
    """wanted plus every GL type their C text names, in registry order."""
    texts = dict(reg.types)
    todo = list(wanted)
    need = set()
    while todo:
        n = todo.pop()
        if n in need:
            continue
        need.add(n)
        for tok in re.findall(r"\bGL\w+", texts[n]):
            if tok in reg.type_names and tok != n:
                todo.append(tok)
    return [(n, t) for n, t in reg.types if n in need]


def generate(reg, names, list_path):
    commands, enums, types = [], [], []
    errors = []
    for name, lineno in names:
        where = f"{list_path}:{lineno}"
        if name in reg.commands or name in reg.enums:
            if name not in reg.core:
                errors.append(f"{where}: {name} is not part of OpenGL {CORE_VERSION[0]}.{CORE_VERSION[1]} core")
            else:
                (commands if name in reg.commands else enums).append(name)
        elif name in reg.type_names:
            types.append(name)
        else:
            errors.append(f"{where}: {name} is not in the GL registry")
    if errors:
        sys.exit("\n".join(errors))
    commands.sort()
    enums.sort()
    wanted = set(types)
    for c in commands:
        wanted.update(reg.commands[c][2])
    version = lambda n: "%d.%d" % reg.core[n]
    pfn = lambda c: "PFN" + c.upper() + "PROC"

    out = []
    w = out.append
    w("/* gl_api.h - GENERATED by cmake/gen_gl_api.py from the Khronos registry")
    w(" * (gl.xml, Debian package khronos-api) for the names in gpu/gl_api.txt.")
    w(" * Do not edit: add a name to gpu/gl_api.txt instead. Include gpu/gl.h,")
    w(" * not this file. */")
    w("#ifndef LPV_GL_API_H")
    w("#define LPV_GL_API_H")
    w("")
    w("#include <KHR/khrplatform.h>")
    w("")
    w("#ifndef APIENTRY")
    w("#define APIENTRY")
    w("#endif")
    w("#ifndef APIENTRYP")
    w("#define APIENTRYP APIENTRY *")
    w("#endif")
    w("")
    w("/* ---- types ---- */")
    for n, t in type_closure(reg, wanted):
        if n == "khrplatform":
            continue
        w(t)
    w("")
    w(f"/* ---- enums ({len(enums)}) ---- */")
    for e in enums:
        w(f"#define {e} {reg.enums[e]}")
    w("")
    w(f"/* ---- commands ({len(commands)}): pointer types ---- */")
    for c in commands:
        ret, params, _ = reg.commands[c]
        w(f"typedef {ret} (APIENTRYP {pfn(c)})({', '.join(params) or 'void'});")
    w("")
    w("/* X(PFN type, GL name) for every command, with the GL version that")
    w(" * brought it into the core profile. */")
    w("#define LPV_GL_FUNCTIONS(X) \\")
    for c in commands:
        w(f"    X({pfn(c)}, {c}) /* {version(c)} */ \\")
    w("    /* end of LPV_GL_FUNCTIONS */")
    w("")
    w("/* The standard names call through the table (gpu/gl_loader.c). */")
    for c in commands:
        w(f"#define {c} lpv_gl_{c}")
    w("")
    w("#endif /* LPV_GL_API_H */")
    return "\n".join(out) + "\n"


def strip_comments_and_strings(src):
    """C/C++ text with comments, string and character literals blanked."""
    pattern = re.compile(r"""//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*'""", re.S)
    return pattern.sub(" ", src)


def used_identifiers(source_dir, skip):
    """Identifiers in the code of every C/C++ file under source_dir, build
    trees (a folder holding CMakeCache.txt), hidden folders and the files
    in skip left out."""
    found = set()
    for dirpath, dirnames, filenames in os.walk(source_dir):
        dirnames[:] = [d for d in dirnames if not d.startswith(".")
                       and not os.path.exists(os.path.join(dirpath, d, "CMakeCache.txt"))]
        for fn in filenames:
            path = os.path.join(dirpath, fn)
            if not fn.endswith(SOURCE_SUFFIXES) or os.path.realpath(path) in skip:
                continue
            with open(path, encoding="utf-8", errors="replace") as f:
                code = strip_comments_and_strings(f.read())
            for tok in re.findall(r"\b[A-Za-z_]\w*", code):
                # The table's own name of a command counts as a use of it.
                found.add(tok[len("lpv_gl_"):] if tok.startswith("lpv_gl_gl") else tok)
    return found


def check_used(names, list_path, source_dir, skip):
    used = used_identifiers(source_dir, {os.path.realpath(p) for p in skip})
    unused = [(n, l) for n, l in names if n not in used]
    for n, l in unused:
        print(f"{list_path}:{l}: {n} is listed but no source uses it: remove it", file=sys.stderr)
    if unused:
        return 1
    print(f"gl_api: all {len(names)} names of {list_path} are used by the sources under {source_dir}")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--list", required=True, help="gpu/gl_api.txt")
    ap.add_argument("--xml", help="the Khronos registry gl.xml")
    ap.add_argument("--out", help="header to write")
    ap.add_argument("--check-used", metavar="SOURCE_DIR", help="fail on listed names the sources do not use")
    ap.add_argument("--skip", action="append", default=[], help="a source file --check-used ignores")
    a = ap.parse_args()
    names = read_list(a.list)
    if a.check_used:
        return check_used(names, a.list, a.check_used, a.skip)
    if not a.xml or not a.out:
        ap.error("--xml and --out are needed to generate")
    text = generate(Registry(a.xml), names, a.list)
    tmp = a.out + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
