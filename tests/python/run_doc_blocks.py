#!/usr/bin/env python3
"""Runs the ```python blocks of a Markdown file in order, in one namespace, from the current
folder (the repository root), and checks what each prints.

A block followed by a ```text block (nothing but blank lines between) must print exactly that
text; a block without one must print nothing. So every number a tutorial shows is what the
code gives. Exit 0 when all blocks ran and matched; 1 with the first difference otherwise.

    python3 tests/python/run_doc_blocks.py docs/python.md
"""
import contextlib
import io
import re
import sys
import traceback

FENCE = re.compile(r"^```(\w*)\s*$")


def blocks(text):
    """(language, code, first line number) of every fenced block, in order."""
    out, lang, lines, start = [], None, [], 0
    for number, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if lang is None and m:
            lang, lines, start = m.group(1), [], number
        elif lang is not None and line.strip() == "```":
            out.append((lang, "\n".join(lines) + "\n", start))
            lang = None
        elif lang is not None:
            lines.append(line)
    return out


def main(path):
    found = blocks(open(path, encoding="utf-8").read())
    namespace = {"__name__": "__doc_blocks__"}
    ran = 0
    for i, (lang, code, line) in enumerate(found):
        if lang != "python":
            continue
        expected = None
        if i + 1 < len(found) and found[i + 1][0] == "text":
            expected = found[i + 1][1]
        printed = io.StringIO()
        try:
            with contextlib.redirect_stdout(printed):
                exec(compile(code, f"{path}:{line}", "exec"), namespace)
        except Exception:  # the block's error, with its place in the file
            traceback.print_exc()
            print(f"{path}:{line}: the python block failed", file=sys.stderr)
            return 1
        ran += 1
        if (expected or "") != printed.getvalue():
            print(f"{path}:{line}: the python block printed\n{printed.getvalue()}"
                  f"the text block after it says\n{expected or ''}", file=sys.stderr)
            return 1
    if ran == 0:
        print(f"{path}: no python block", file=sys.stderr)
        return 1
    print(f"{path}: {ran} python blocks ran, their output as shown")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
