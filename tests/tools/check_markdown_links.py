#!/usr/bin/env python3
"""Checks every relative link and image of the given Markdown files (./setup.sh docs, CI): the
file it names exists, and an anchor into a Markdown file names one of its headings (slugged as
MkDocs' toc extension does). Links to web addresses are not followed. Exit 1 with one line per
broken link."""
import os
import re
import sys

LINK = re.compile(r'!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+"[^"]*")?\)')


def slug(title):
    # Python-Markdown's toc slugify: lower case, punctuation dropped, spaces to hyphens.
    text = re.sub(r'[^\w\s-]', '', title.strip().lower())
    return re.sub(r'[-\s]+', '-', text).strip('-')


def anchors(path):
    found, fence = set(), False
    with open(path, encoding='utf-8') as f:
        for line in f:
            if line.startswith('```'):
                fence = not fence
            elif not fence and line.startswith('#'):
                found.add(slug(line.lstrip('#')))
    return found


def check(md):
    broken = []
    base = os.path.dirname(md)
    fence = False
    with open(md, encoding='utf-8') as f:
        for number, line in enumerate(f, 1):
            if line.startswith('```'):
                fence = not fence
            if fence:
                continue
            for target in LINK.findall(line):
                if re.match(r'^[a-z][a-z0-9+.-]*:', target) or target.startswith('#'):
                    continue
                path, _, anchor = target.partition('#')
                full = os.path.normpath(os.path.join(base, path))
                if not os.path.exists(full):
                    broken.append(f'{md}:{number}: {target}: no such file')
                elif anchor and full.endswith('.md') and anchor not in anchors(full):
                    broken.append(f'{md}:{number}: {target}: no heading "{anchor}"')
    return broken


def main():
    broken = [b for md in sys.argv[1:] for b in check(md)]
    for b in broken:
        print(b)
    return 1 if broken else 0


if __name__ == '__main__':
    sys.exit(main())
