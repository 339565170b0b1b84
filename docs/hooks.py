"""A hook of the site's build (mkdocs.yml's ``hooks``): the docstrings' Sphinx roles
(:func:`name`, :class:`name`, ...), which Markdown renders as the role's text before a code
span, become cross-references to the object's entry in the API reference (an unqualified
name is looked up under ``stewart.``), or the code span alone where the reference has no
entry for it."""

from __future__ import annotations

import re

_ROLE = re.compile(r":(?:py:)?(?:func|class|mod|data|meth|attr|exc|obj):<code>~?\.?([\w.]+?)(\(\))?</code>")


def _reference(match: re.Match) -> str:
    name, call = match.group(1), match.group(2) or ""
    identifier = name if name.startswith("stewart.") or name == "stewart" else f"stewart.{name}"
    return f'<autoref identifier="{identifier}" optional><code>{name}{call}</code></autoref>'


def on_page_content(html: str, **kwargs) -> str:
    return _ROLE.sub(_reference, html)
