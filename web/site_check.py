#!/usr/bin/env python3
"""The course site's static checks (web/site-test.sh runs them on web/site.sh's output): every
relative link and image of every page, and every file a style sheet names, is a file the site has, and
every anchor a link names is on its page; every
chapter with shell blocks has links into the page; the answers are in the site only when asked for.
Writes the page's links (`mirador/?…`), each once, with the first page it is on, for the browser part
of the test. Exits 1 with every problem listed."""

import argparse
import html.parser
import pathlib
import re
import sys
import urllib.parse


class Page(html.parser.HTMLParser):
    """A page's link targets, image sources and anchors."""

    def __init__(self):
        super().__init__()
        self.targets = []
        self.anchors = set()
        self.live = 0
        self.math = 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.anchors.add(attrs["id"])
        if tag == "a" and attrs.get("name"):
            self.anchors.add(attrs["name"])
        for key in ("href", "src"):
            if attrs.get(key) and tag in ("a", "img", "script", "link"):
                self.targets.append(attrs[key])
        if "mirador-live" in (attrs.get("class") or ""):
            self.live += 1
        if "math-display" in (attrs.get("class") or ""):
            self.math += 1


def parse(path):
    page = Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("site", type=pathlib.Path)
    parser.add_argument("--links", type=pathlib.Path, required=True, help="write the page's links here")
    parser.add_argument("--answers", action="store_true", help="the site was built with --answers")
    args = parser.parse_args()
    site = args.site.resolve()
    problems, links = [], []
    pages = {path: parse(path) for path in sorted(site.rglob("*.html")) if "mirador" not in path.relative_to(site).parts}
    for path, page in pages.items():
        name = path.relative_to(site)
        for target in page.targets:
            url = urllib.parse.urlsplit(target)
            if url.scheme or target.startswith("//"):
                continue
            resolved = (path.parent / urllib.parse.unquote(url.path)).resolve() if url.path else path
            if not resolved.is_relative_to(site):
                problems.append(f"{name}: {target} leaves the site")
                continue
            if resolved.is_dir():
                resolved = resolved / "index.html"
            if not resolved.exists():
                problems.append(f"{name}: {target} names {resolved.relative_to(site)}, which the site does not have")
                continue
            if resolved.relative_to(site).parts[0] == "mirador" and url.query:
                links.append(f"{name}\t{url.query}")
            if url.fragment and resolved.suffix == ".html" and resolved in pages:
                if urllib.parse.unquote(url.fragment) not in pages[resolved].anchors:
                    problems.append(f"{name}: {target}: {resolved.relative_to(site)} has no anchor {url.fragment}")
    # What the style sheets name (fonts, images): `url(…)`, relative to the sheet.
    for sheet in sorted(site.rglob("*.css")):
        if "mirador" in sheet.relative_to(site).parts:
            continue
        for target in re.findall(r"url\(\s*['\"]?([^'\")]+)", sheet.read_text(encoding="utf-8")):
            if target.startswith("data:") or urllib.parse.urlsplit(target).scheme:
                continue
            resolved = (sheet.parent / urllib.parse.unquote(urllib.parse.urlsplit(target).path)).resolve()
            if not resolved.exists():
                # KaTeX names each font thrice (WOFF2, WOFF, TTF); a browser takes the first it reads.
                if resolved.suffix in (".woff", ".ttf") and resolved.with_suffix(".woff2").exists():
                    continue
                problems.append(f"{sheet.relative_to(site)}: {target} is not in the site")
    chapters = sorted(site.glob("[0-9][0-9]-*.html"))
    if len(chapters) < 12:
        problems.append(f"{len(chapters)} chapters, not 12")
    for chapter in chapters:
        if pages[chapter].live == 0:
            problems.append(f"{chapter.name}: no link into the page under any command")
    answers = (site / "answers.html").exists() or any("answers" in p.name for p in (site / "source").rglob("*"))
    if answers != args.answers:
        problems.append("the answers are in the site" if answers else "the answers are not in the site")
    math = sum(page.math for page in pages.values())
    unique = {}
    for line in links:
        unique.setdefault(line.split("\t")[1], line)
    args.links.write_text("".join(f"{line}\n" for line in unique.values()))
    print(f"{len(pages)} pages, {sum(len(p.targets) for p in pages.values())} links checked, "
          f"{len(links)} into the page ({len(unique)} different), {math} formulas")
    for problem in problems:
        print(f"problem: {problem}", file=sys.stderr)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
