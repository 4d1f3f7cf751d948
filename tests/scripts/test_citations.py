#!/usr/bin/env python3
"""The repository cites no document outside itself (docs/conventions.md, section 12).

Scans every file of the source tree (build trees and .git left out, binary files and fuzz
inputs included) for citations of documents kept outside the repository: their file names
with or without ".md", spelled with a section, practice or path, and paths into the folder
beside the repository. The only paths there that may appear are the ones programs and tests
read at run time (the real-arm data and the Linux VM probe). Prints each hit as
path:line: text and exits 1 when there is one.

Usage: test_citations.py SOURCE_DIR
"""
import os
import re
import sys

OUTSIDE_DOCS = re.compile(
    rb'\b(?:DESIGN|PHYSICS|STYLE)(?:\.md|/|:| section| sec\.| practice| \d|\'s)')
OUTSIDE_PATH = re.compile(rb'(?:\.\./|/work/)shared\b(?!/realdata|/linux-vm)')

SKIP_DIRS = {'.git', 'build'}
THIS = os.path.join('tests', 'scripts', 'test_citations.py')


def scan(root):
    hits = []
    for top, dirs, files in os.walk(root):
        rel_top = os.path.relpath(top, root)
        dirs[:] = sorted(d for d in dirs
                         if d not in SKIP_DIRS and not d.startswith('build-') and
                         not os.path.exists(os.path.join(top, d, 'CMakeCache.txt')))
        for name in sorted(files):
            rel = os.path.normpath(os.path.join(rel_top, name))
            if rel == THIS:
                continue
            with open(os.path.join(top, name), 'rb') as f:
                data = f.read()
            for no, line in enumerate(data.split(b'\n'), 1):
                if not (OUTSIDE_DOCS.search(line) or OUTSIDE_PATH.search(line)):
                    continue
                hits.append('%s:%d: %s' % (rel, no, line.strip()[:120].decode(
                    'utf-8', 'backslashreplace')))
    return hits


def self_test():
    """The patterns catch the spellings the repository used to have, and spare the
    run-time data paths."""
    cited = [b'(DESIGN.md section 3)', b'DESIGN section 3b', b"PHYSICS.md's plant table",
             b'(STYLE 2)', b'STYLE.md practice 9', b'DESIGN/lib: y =',
             b'see ../shared/DESIGN.md', b'/work/shared/PHYSICS.md']
    clean = [b'../shared/realdata/ur5-jacobi', b'../shared/linux-vm/run.sh',
             b'a clang-format style', b'DESIGNER', b'the design document']
    for text in cited:
        assert OUTSIDE_DOCS.search(text) or OUTSIDE_PATH.search(text), text
    for text in clean:
        assert not OUTSIDE_DOCS.search(text) and not OUTSIDE_PATH.search(text), text


def main():
    if len(sys.argv) != 2:
        sys.exit('usage: test_citations.py SOURCE_DIR')
    self_test()
    hits = scan(sys.argv[1])
    for h in hits:
        print(h)
    print('%d citation%s of documents outside the repository' %
          (len(hits), '' if len(hits) == 1 else 's'))
    return 1 if hits else 0


if __name__ == '__main__':
    sys.exit(main())
