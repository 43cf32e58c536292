#!/usr/bin/env python3
"""The documentation resolves: every relative link and image in README.md and
docs/*.md names a file of the repository (and, with #anchor, a heading of it),
and every code comment that cites the design ("docs/design.md 2.7a" or
docs/design.md "Live ingest") names a section docs/design.md has. The README
stays a front door (at most 250 lines). Run by ctest (tests/docs_test)."""

import pathlib
import re
import sys

SELF = pathlib.Path(__file__).resolve()
ROOT = SELF.parent.parent
README_MAX_LINES = 250
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
CODE_DIRS = ("common", "services", "cli", "bench", "tests", "proto", "python", "web",
             "deploy", "scripts")
CODE_SUFFIXES = {".h", ".cc", ".proto", ".py", ".sh", ".js", ".txt", ".yml", ".yaml"}
# "docs/design.md 2.7a", "docs/design.md sections 2.2, 2.3" (the first number is
# checked), 'docs/design.md "Fused candidates"'.
CITE_NUMBER = re.compile(r"design\.md (?:sections? )?(\d+(?:\.\d+[a-z]?)?)")
CITE_TITLE = re.compile(r'design\.md\s+"([^"]+)')


def headings(path):
    """The Markdown headings of a file outside code fences, as text."""
    result, in_fence = [], False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            in_fence = not in_fence
        elif not in_fence and re.match(r"#{1,6} ", line):
            result.append(line.lstrip("#").strip())
    return result


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation but - and _ dropped,
    spaces to hyphens."""
    text = re.sub(r"[`*]", "", heading).lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def check_links(doc, errors):
    in_fence = False
    for number, line in enumerate(doc.read_text(encoding="utf-8").splitlines(), 1):
        if line.startswith("```"):
            in_fence = not in_fence
        if in_fence:
            continue
        for target in LINK.findall(line):
            if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
                continue
            file_part, _, anchor = target.partition("#")
            path = (doc.parent / file_part).resolve() if file_part else doc
            where = f"{doc.relative_to(ROOT)}:{number}: link {target}"
            if not path.exists():
                errors.append(f"{where}: no such file")
            elif ROOT not in path.parents and path != ROOT:
                errors.append(f"{where}: outside the repository")
            elif anchor and path.suffix == ".md" and anchor not in map(slug, headings(path)):
                errors.append(f"{where}: no heading with anchor #{anchor} in {file_part or doc.name}")


def check_citations(errors):
    design = headings(ROOT / "docs" / "design.md")
    numbers = {h.split()[0].rstrip(".") for h in design if re.match(r"\d", h)}
    for directory in CODE_DIRS:
        for path in sorted((ROOT / directory).rglob("*")):
            if path.suffix not in CODE_SUFFIXES or not path.is_file() or path == SELF:
                continue
            text = path.read_text(encoding="utf-8", errors="replace")
            if "DESIGN.md" in text:
                errors.append(f"{path.relative_to(ROOT)}: cites DESIGN.md, which is not in the "
                              "repository (docs/design.md is)")
            for number, line in enumerate(text.splitlines(), 1):
                where = f"{path.relative_to(ROOT)}:{number}"
                for section in CITE_NUMBER.findall(line):
                    if section not in numbers:
                        errors.append(f"{where}: docs/design.md has no section {section}")
                for title in CITE_TITLE.findall(line):
                    if not any(title in h for h in design):
                        errors.append(f'{where}: docs/design.md has no section "{title}"')


def main():
    errors = []
    docs = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
    for doc in docs:
        check_links(doc, errors)
    readme_lines = len((ROOT / "README.md").read_text(encoding="utf-8").splitlines())
    if readme_lines > README_MAX_LINES:
        errors.append(f"README.md: {readme_lines} lines, more than {README_MAX_LINES}: details "
                      "belong in docs/")
    check_citations(errors)
    for error in errors:
        print(error)
    print(f"docs_test: {len(docs)} documents, {len(errors)} errors")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
