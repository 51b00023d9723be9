"""A sphinx-gallery image scraper for ``nonsmooth.plot``'s figures.

``nonsmooth.plot`` makes its figures with the pyplot-free ``matplotlib.figure.Figure`` API, so
sphinx-gallery's matplotlib scraper (which asks pyplot for its open figures) sees none. This
scraper records every Figure created while an example runs, in creation order, and saves each
once after the code block that made it.
"""

from __future__ import annotations

import matplotlib.figure

_created: list = []
_init = matplotlib.figure.Figure.__init__


def _recording_init(self, *args, **kwargs):
    _init(self, *args, **kwargs)
    _created.append(self)


matplotlib.figure.Figure.__init__ = _recording_init


def scrape(block, block_vars, gallery_conf, **kwargs):
    """Save the figures made by this code block; the rst that shows them."""
    from sphinx_gallery.scrapers import figure_rst

    paths = []
    for fig, path in zip(list(_created), block_vars["image_path_iterator"]):
        fig.savefig(path, dpi=90)
        paths.append(path)
    _created.clear()
    return figure_rst(paths, gallery_conf["src_dir"])


def reset(gallery_conf, fname):
    """Forget figures of an earlier example."""
    _created.clear()
