#!/usr/bin/env python3
"""check_sizes.py SOURCE_DIR: the house's size rules, checked like the no-heap rule.

No production C file (lib/, can/, io/, desk/, tools/, firmware/, host_sim/, python/src/) over
MAX_FILE_LINES lines, and no function in one over MAX_FUNCTION_LINES lines (from its opening
brace to its closing one: the codebase's style puts both at the start of a line). Tests,
examples and benchmarks are exempt, and so is a file that holds a data table only (none
today). Prints every breach with its file, line and size; exit 1 if there is any.
"""
import os
import re
import sys

MAX_FILE_LINES = 1000
MAX_FUNCTION_LINES = 150
FOLDERS = ("lib", "can", "io", "desk", "tools", "firmware", "host_sim", os.path.join("python", "src"))
SIGNATURE = re.compile(r"\b([A-Za-z_][A-Za-z_0-9]*)\s*\(")


def functions(lines):
    """(name, first line, line count) of every function body in a C file."""
    i = 0
    while i < len(lines):
        if lines[i].rstrip() == "{":
            start = i
            end = i + 1
            while end < len(lines) and lines[end].rstrip() != "}":
                end += 1
            k = start - 1
            while k >= 0 and not SIGNATURE.search(lines[k]):
                k -= 1
            name = SIGNATURE.search(lines[k]).group(1) if k >= 0 else "?"
            yield name, start + 1, end - start + 1
            i = end
        i += 1


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: check_sizes.py SOURCE_DIR")
    root = sys.argv[1]
    breaches = []
    files = 0
    for folder in FOLDERS:
        for base, _, names in os.walk(os.path.join(root, folder)):
            for name in sorted(names):
                if not name.endswith(".c"):
                    continue
                path = os.path.join(base, name)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8") as f:
                    lines = f.read().split("\n")
                files += 1
                if len(lines) - 1 > MAX_FILE_LINES:
                    breaches.append("%s: %d lines (at most %d)"
                                    % (rel, len(lines) - 1, MAX_FILE_LINES))
                for fn, first, count in functions(lines):
                    if count > MAX_FUNCTION_LINES:
                        breaches.append("%s:%d: function %s: %d lines (at most %d)"
                                        % (rel, first, fn, count, MAX_FUNCTION_LINES))
    for b in breaches:
        print(b)
    if breaches:
        sys.exit("check_sizes: %d breach(es) in %d files" % (len(breaches), files))
    print("check_sizes: %d production C files, none over %d lines, no function over %d"
          % (files, MAX_FILE_LINES, MAX_FUNCTION_LINES))


if __name__ == "__main__":
    main()
