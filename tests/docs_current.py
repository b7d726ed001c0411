#!/usr/bin/env python3
"""docs_current.py - a generated page is what its generator prints now.

  docs_current.py PAGE -- COMMAND [ARGS...]

Runs COMMAND and compares its standard output with PAGE byte for byte; on a
difference prints a unified diff and the command that regenerates the page,
and exits 1. Used for docs/knobs.md (`lpvd knobs --markdown`), so a knob's
documented range or default cannot drift from its row in the table.
"""
import difflib
import os
import subprocess
import sys


def main():
    if len(sys.argv) < 4 or sys.argv[2] != '--':
        print(__doc__.strip(), file=sys.stderr)
        return 2
    page, cmd = sys.argv[1], sys.argv[3:]
    got = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    with open(page, encoding='utf-8') as f:
        have = f.read()
    if got == have:
        print('docs_current: %s is current' % page)
        return 0
    sys.stdout.writelines(difflib.unified_diff(have.splitlines(True), got.splitlines(True),
                                               page, ' '.join(os.path.basename(c) if i == 0 else c
                                                              for i, c in enumerate(cmd))))
    print('\ndocs_current: %s differs from what its generator prints; regenerate it with\n  %s > %s'
          % (page, ' '.join(cmd), page))
    return 1


if __name__ == '__main__':
    sys.exit(main())
