"""What the plot scripts share (Debian's matplotlib, non-interactive Agg backend):
`plt`, and `save`, which writes a figure atomically so that a reader never sees half a
PNG."""

import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402,F401


def save(fig, path):
    """Write @p fig to @p path (PNG, 110 dpi, tight box) through a temporary file."""
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, path)
