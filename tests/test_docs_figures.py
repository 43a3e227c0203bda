"""The gallery: every picture in docs/figures/ is shown by a docs page, and every picture a page
shows exists (``make figures`` regenerates the screenshots, ``make report`` the results figures)."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"!\[[^\]]*\]\(((?:docs/)?figures/[^)\s]+\.png)\)")


def _linked() -> dict[str, list[str]]:
    found: dict[str, list[str]] = {}
    for page in PAGES:
        for target in LINK.findall(page.read_text(encoding="utf-8")):
            found.setdefault(Path(target).name, []).append(page.name)
    return found


def test_every_figure_is_linked_from_a_page():
    linked = _linked()
    pictures = sorted(p.name for p in FIGURES.glob("*.png"))
    assert len(pictures) >= 20
    assert [p for p in pictures if p not in linked] == []


def test_every_linked_figure_exists():
    assert [name for name in _linked() if not (FIGURES / name).exists()] == []


def test_gallery_names_the_screenshots_the_docs_show():
    """app/gallery.py writes the window and video pictures that docs/app.md shows."""
    source = (ROOT / "app" / "gallery.py").read_text(encoding="utf-8")
    app_page = {name for name, pages in _linked().items() if "app.md" in pages}
    for name in app_page - {"app.png"}:
        stem = name.removesuffix(".png")
        assert name in source or stem.split("_", 1)[1] in source, name
