#!/usr/bin/env python3
"""Lists C++ function bodies longer than a limit (default 80 lines) in the given folders.

A function may be longer when the comment block right above its signature says why and holds the
words "long function". Exit code 1 when a function is too long without such a comment (ctest runs
this over stack/ and scenarios/). A heuristic brace scanner, not a C++ parser: it strips comments
and literals, treats a brace after a closing parenthesis at namespace or class level as a function
body, and counts the body's lines from the signature to the closing brace.
"""
import argparse
import pathlib
import re
import sys

NON_FUNCTION = re.compile(r"\b(namespace|class|struct|enum|union)\b[^()]*$|extern\s*\"C\"\s*$|=\s*$")


def strip(text):
    """Blanks comments, string and character literals, keeping line structure."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and re.match(r'R"([^(]*)\(', text[i:]):
            delim = re.match(r'R"([^(]*)\(', text[i:]).group(1)
            j = text.find(")" + delim + '"', i)
            j = n if j < 0 else j + len(delim) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (min(j, n) - i - 1) + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """Yields (first line, last line, signature text) of each function body in a file."""
    raw = path.read_text(encoding="utf-8", errors="replace")
    # Preprocessor lines end no statement: blank them (keeping their newlines).
    text = re.sub(r"(?m)^[ \t]*#.*$", lambda m: " " * len(m.group(0)), strip(raw))
    stack = []          # per open brace: True if it opened a function body
    depth_in_function = 0
    statement_start = 0
    start_line = None
    signature = ""
    line = 1
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c in ";":
            if depth_in_function == 0:
                statement_start = i + 1
        elif c == "{":
            if depth_in_function > 0:
                stack.append(False)
                depth_in_function += 1
                continue
            head = text[statement_start:i].strip()
            is_function = ")" in head and not NON_FUNCTION.search(head.split("(")[0] + "(") \
                and not re.search(r"\b(namespace|class|struct|enum|union)\b", head.split("(")[0])
            if is_function and not head.rstrip().endswith("="):
                stack.append(True)
                depth_in_function = 1
                start_line = raw.count("\n", 0, statement_start + len(text[statement_start:i]) - len(text[statement_start:i].lstrip())) + 1
                signature = " ".join(head.split())[:100]
            else:
                stack.append(False)
                statement_start = i + 1
        elif c == "}":
            if not stack:
                continue
            opened_function = stack.pop()
            if depth_in_function > 0:
                depth_in_function -= 1
                if depth_in_function == 0 and opened_function:
                    yield start_line, line, signature
                    statement_start = i + 1
            else:
                statement_start = i + 1


def explained(lines, first_line):
    """Whether the comment block above line `first_line` (1-based) explains the length."""
    k = first_line - 2
    block = []
    while k >= 0 and (lines[k].strip().startswith("//") or lines[k].strip().startswith("template")):
        block.append(lines[k])
        k -= 1
    return "long function" in " ".join(block).lower()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--limit", type=int, default=80)
    parser.add_argument("--all", action="store_true", help="also list explained long functions")
    args = parser.parse_args()
    too_long = 0
    for folder in args.folders:
        for path in sorted(pathlib.Path(folder).rglob("*")):
            if path.suffix not in (".cc", ".h", ".cpp", ".hpp"):
                continue
            lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
            for first, last, signature in functions(path):
                length = last - first + 1
                if length <= args.limit:
                    continue
                ok = explained(lines, first)
                if not ok:
                    too_long += 1
                if not ok or args.all:
                    print(f"{path}:{first}: {length} lines{' (explained)' if ok else ''}: {signature}")
    if too_long:
        print(f"{too_long} functions longer than {args.limit} lines without a comment saying why")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
