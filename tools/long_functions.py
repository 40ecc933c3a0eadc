#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Lists the functions over a length limit in the production code (CI: tools/check_style.sh).

    tools/long_functions.py                 every function over 80 lines, longest first
    tools/long_functions.py --max-count 5   the same, and fails when there are more than 5

A function's length is its lines from the line that names it to its closing brace (C, C++), or
from its `def` to its last line (Python), blank lines and comments included. Read: firmware/,
hal/, host_sim/, targets/, base/ and tools/, without tests (tests/, test_*, *_test.*), generated
codecs (a `generated` folder) and vendored code. C and C++ are read with a brace scanner, not a
compiler: comments, strings and preprocessor lines are passed over, and a `{` opens a function
when the text before it ends in a parameter list at file, namespace, extern "C" or class level.
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
from pathlib import Path

ROOTS = ("base", "firmware", "hal", "host_sim", "targets", "tools")
C_SUFFIXES = {".c", ".h", ".cpp", ".hpp", ".cc"}
CONTROL = {"if", "for", "while", "switch", "catch", "do", "else", "return", "sizeof"}
SCOPE_WORDS = re.compile(r"\b(namespace|class|struct|union|enum)\b|extern\s*\"C\"")


def is_production(path: str) -> bool:
    parts = Path(path).parts
    name = parts[-1]
    if any(p in ("tests", "test", "generated", "vendor", "third_party") for p in parts):
        return False
    return not (name.startswith("test_") or re.search(r"_test\.\w+$", name))


def blank_out(text: str) -> str:
    """The text with comments, string and character literals and preprocessor lines turned into
    spaces, newlines kept, so that offsets and line numbers stay."""
    out = list(text)
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            # A preprocessor line, with its continuations.
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out[i] = " "
                    i += 2
                    continue
                out[i] = " "
                i += 1
            continue
        if c == "\n":
            line_start = True
            i += 1
            continue
        if not c.isspace():
            line_start = False
        if text.startswith("//", i):
            while i < n and text[i] != "\n":
                out[i] = " "
                i += 1
            continue
        if text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            for j in range(i, end):
                if text[j] != "\n":
                    out[j] = " "
            i = end
            continue
        raw = re.match(r'R"([^(\s]*)\(', text[i:])
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = text.find(")" + raw.group(1) + '"', i)
            end = n if end < 0 else end + len(raw.group(1)) + 2
            for j in range(i, end):
                if text[j] != "\n":
                    out[j] = " "
            i = end
            continue
        if c in "\"'":
            # A digit separator (1'000) is not a character literal.
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            for k in range(i + 1, min(j, n)):
                out[k] = " "
            i = j + 1
            continue
        i += 1
    return "".join(out)


def function_name(head: str) -> str | None:
    """The function's name when `head`, the code between the previous `;`, `{` or `}` and a `{`,
    is a function's signature; None otherwise."""
    h = " ".join(head.split())
    if not h or "=" in h.split("(")[0] or h.endswith("="):
        return None
    # Trailing qualifiers and a constructor's initializer list.
    h = re.sub(r"\)\s*(const|noexcept|override|final|volatile|&|&&|\s)*(->[^{]*)?$", ")", h)
    init = re.search(r"\)\s*:\s*[\w:]+\s*[({]", h)
    if init:
        h = h[: init.start() + 1]
    if not h.endswith(")"):
        return None
    # The name is the identifier before the parameter list's opening parenthesis.
    depth = 0
    for k in range(len(h) - 1, -1, -1):
        if h[k] == ")":
            depth += 1
        elif h[k] == "(":
            depth -= 1
            if depth == 0:
                m = re.search(r"([~\w:]+|operator\s*\S+)\s*$", h[:k])
                if not m:
                    return None
                name = m.group(1)
                if name.split("::")[-1] in CONTROL or name in CONTROL:
                    return None
                if SCOPE_WORDS.search(h[:k]) and "(" not in h[:k]:
                    return None
                return name
    return None


def c_functions(path: Path):
    text = path.read_text(errors="replace")
    code = blank_out(text)
    line_of = [0] * (len(code) + 1)
    line = 1
    for i, ch in enumerate(code):
        line_of[i] = line
        if ch == "\n":
            line += 1
    line_of[len(code)] = line
    # Stack of open blocks: ("scope" | "func" | "other", name, start offset).
    stack: list[tuple[str, str, int]] = []
    head_start = 0
    for i, ch in enumerate(code):
        if ch in ";":
            head_start = i + 1
        elif ch == "{":
            head = code[head_start:i]
            in_function = any(kind in ("func", "other") for kind, _, _ in stack)
            if not in_function and re.search(r"\)\s*:\s*[^;]*[\w>]\s*$", head) and "?" not in head:
                # A member's brace initializer in a constructor's initializer list: the head goes on.
                stack.append(("init", "", i))
                continue
            name = None if in_function else function_name(head)
            if name is not None:
                start = head_start + len(head) - len(head.lstrip())
                # The line that names the function: where its parameter list begins.
                paren = code.find(name.split("::")[-1], start)
                stack.append(("func", name, paren if paren >= 0 else start))
            elif not in_function and (SCOPE_WORDS.search(head) or not head.strip()):
                stack.append(("scope", "", i))
            else:
                stack.append(("other", "", i))
            head_start = i + 1
        elif ch == "}":
            if stack:
                kind, name, start = stack.pop()
                if kind == "init":
                    continue
                if kind == "func":
                    yield name, line_of[start], line_of[i]
            head_start = i + 1


def py_functions(path: Path):
    try:
        tree = ast.parse(path.read_text(errors="replace"))
    except SyntaxError:
        return
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield node.name, node.lineno, node.end_lineno


def production_files(root: Path) -> list[str]:
    out = subprocess.run(["git", "ls-files", "--", *ROOTS], cwd=root, capture_output=True, text=True, check=True)
    return [f for f in out.stdout.split() if is_production(f)]


def long_functions(root: Path, limit: int):
    found = []
    for f in production_files(root):
        p = root / f
        if p.suffix in C_SUFFIXES:
            funcs = c_functions(p)
        elif p.suffix == ".py":
            funcs = py_functions(p)
        else:
            continue
        for name, first, last in funcs:
            length = last - first + 1
            if length > limit:
                found.append((length, f, first, name))
    found.sort(key=lambda x: (-x[0], x[1], x[2]))
    return found


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lines", type=int, default=80, help="the length limit (default 80)")
    ap.add_argument("--max-count", type=int, default=None, help="fail when more functions are over the limit")
    args = ap.parse_args(argv)
    root = Path(__file__).resolve().parent.parent
    found = long_functions(root, args.lines)
    for length, f, first, name in found:
        print(f"{length:5d}  {f}:{first}  {name}")
    print(f"{len(found)} functions over {args.lines} lines")
    if args.max_count is not None and len(found) > args.max_count:
        print(f"more than {args.max_count}: cut the new ones into named steps", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
