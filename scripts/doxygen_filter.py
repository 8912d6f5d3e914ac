#!/usr/bin/python3
"""Doxygen's INPUT_FILTER for jelly's public headers (scripts/build_docs.py runs Doxygen with
it): the headers keep the project's plain `//` comments, and this hands Doxygen the same text
with the comments that document a declaration marked as documentation:

  - the comment at the top of a header (after `#pragma once`) documents the file (`/// \\file`);
  - a run of `//` lines directly above a declaration (no blank line between) documents it;
  - a `//` comment at the end of a member's, an enumerator's or a one-line function's line
    (`int n = 0;  // ...`), and the comment lines aligned under it, document it (`///<`).

Comments inside function bodies and initializers, comments followed by a blank line, a
preprocessor line, a closing brace, an access label or a namespace stay plain comments. Line numbers are
kept (one output line per input line), so Doxygen's warnings point at the header's own lines.

Usage: doxygen_filter.py HEADER  (prints the filtered text on stdout, as Doxygen expects)
"""
import os
import re
import sys

SCOPE_HEAD = re.compile(r"^(template\s*<.*>\s*)?(class|struct|union|enum|namespace)\b")
ENUMERATOR = re.compile(r"^\s*k[A-Z]\w*(\s*=\s*[^,;{}()]+)?\s*,?\s*$")
PLAIN = re.compile(r"^//\s*(clang-format|NOLINT)")
# Comments write placeholders as <name> or <body>: text for Doxygen, not HTML tags.
PLACEHOLDER = re.compile(r"<(/?)(?!(?:b|i|em|code|pre|br|p|sub|sup|tt)>)([A-Za-z_][\w.]*)>")


def doc(text):
    """A comment's text as Doxygen documentation: placeholders escaped."""
    return PLACEHOLDER.sub(lambda m: "\\<" + m.group(1) + m.group(2) + "\\>", text)


def split_comment(line):
    """(code, comment) of a line: the comment starts at the first `//` outside a string or
    character literal and outside a `/* */` comment on that line; '' when there is none."""
    i, quote = 0, None
    while i < len(line):
        c = line[i]
        if quote:
            if c == "\\":
                i += 2
                continue
            if c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif line.startswith("/*", i):
            end = line.find("*/", i + 2)
            i = len(line) if end < 0 else end + 2
            continue
        elif line.startswith("//", i):
            return line[:i], line[i:]
        i += 1
    return line, ""


def braces(code):
    """The `{` and `}` of a line's code in order, outside string and character literals and
    `/* */` comments."""
    out, i, quote = [], 0, None
    while i < len(code):
        c = code[i]
        if quote:
            if c == "\\":
                i += 2
                continue
            if c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif code.startswith("/*", i):
            end = code.find("*/", i + 2)
            i = len(code) if end < 0 else end + 2
            continue
        elif c in "{}":
            out.append((i, c))
        i += 1
    return out


def documents_next(line):
    """Whether a comment directly above `line` may document it."""
    s = line.strip()
    if not s or s.startswith("#") or s.startswith("}") or s.startswith("//"):
        return False
    # a section's comment above `namespace jelly {` stays plain: the namespace has its own page
    return not re.match(r"^((public|private|protected)\s*:|namespace\b)", s)


def filter_header(lines, name):
    """The filtered lines of the header `name` (its path in the repository)."""
    out = list(lines)
    n = len(lines)
    # 1. The file's own comment: the first comment run before any code.
    i = 0
    while i < n and (not lines[i].strip() or lines[i].startswith("#pragma")):
        i += 1
    if i < n and lines[i].startswith("//") and not lines[i].startswith("///"):
        out[i] = f"/// \\file {name} " + doc(lines[i][2:].lstrip())
        i += 1
        while i < n and lines[i].startswith("//"):
            out[i] = "///" + doc(lines[i][2:])
            i += 1
    first_code = i

    # 2. Walk the code, tracking whether we are inside a function body or an initializer
    # (where comments stay plain) or in a namespace, class or enum (where they may document).
    stack = []  # True for a body/initializer, False for a scope
    head = ""  # the code since the last ';', '{' or '}' at this level
    trailing_column = None  # the column of the last line's `///<` comment, for continuations
    for i in range(first_code, n):
        line = lines[i]
        code, comment = split_comment(line)
        in_body = any(stack)
        stripped = code.strip()
        if comment and not stripped:
            # a comment-only line
            column = len(line) - len(line.lstrip())
            if in_body or comment.startswith("///") or PLAIN.match(comment):
                trailing_column = None
                continue
            if trailing_column is not None and column == trailing_column:
                out[i] = line[:column] + "///<" + doc(comment[2:])
                continue
            trailing_column = None
            j = i
            while j < n and lines[j].strip().startswith("//"):
                j += 1
            if j < n and documents_next(lines[j]):
                out[i] = line[:column] + "///" + doc(comment[2:])
            continue
        trailing_column = None
        if stripped.startswith("#"):
            continue
        if comment and not in_body and not comment.startswith("///") \
                and not PLAIN.match(comment):
            ends_member = stripped.endswith(";") or stripped.endswith(",")
            # a function defined on its line: `int size() const { return n_; }  // ...`
            marks = [b for _, b in braces(code)]
            ends_member |= stripped.endswith("}") and bool(marks) and marks[0] == "{" \
                and marks.count("{") == marks.count("}")
            if ends_member or (stack and ENUMERATOR.match(stripped)):
                out[i] = code + "///<" + doc(comment[2:])
                trailing_column = len(code)
        # braces of this line, in order
        last = 0
        for position, brace in braces(code):
            head += " " + code[last:position]
            last = position + 1
            if brace == "{":
                h = head.strip()
                h = re.sub(r"^(public|private|protected)\s*:\s*", "", h)
                scope = bool(SCOPE_HEAD.match(h)) and "=" not in h and "(" not in h
                stack.append(in_body or not scope)
                in_body = any(stack)
            else:
                if stack:
                    stack.pop()
                in_body = any(stack)
            head = ""
        rest = code[last:]
        head += " " + rest
        if ";" in rest:
            head = rest.rsplit(";", 1)[1]
    return out


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as f:
        lines = f.read().split("\n")
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    name = os.path.relpath(os.path.abspath(sys.argv[1]), repo)
    sys.stdout.write("\n".join(filter_header(lines, name)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
