"""The confusion matrix of a field batch as a picture: observed classes down, predicted across, counts in cells."""

from __future__ import annotations

__all__ = ["plot_confusion"]


def plot_confusion(sc: dict, path: str) -> str | None:
    """Write the model's confusion matrix (``scores.json``'s ``model``) beside the baselines' scores; return the path
    (None when no case ran)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    m = sc["model"]
    if not m["n"]:
        return None
    conf = m["confusion"]
    counts = np.array(conf["counts"], dtype=float)
    fig, ax = plt.subplots(figsize=(1.2 * len(conf["columns"]) + 2.5, 3.6))
    share = counts / np.maximum(counts.sum(axis=1, keepdims=True), 1.0)
    ax.imshow(share, cmap="Blues", vmin=0.0, vmax=1.0)
    for i in range(counts.shape[0]):
        for j in range(counts.shape[1]):
            ax.text(j, i, f"{int(counts[i, j])}", ha="center", va="center",
                    color="white" if share[i, j] > 0.6 else "black")
    ax.set_xticks(range(len(conf["columns"])), conf["columns"])
    ax.set_yticks(range(len(conf["rows"])), conf["rows"])
    ax.set_xlabel("predicted by the model (shade: share of each observed class)")
    ax.set_ylabel("observed in the field")

    def ba(k):
        v = sc[k]["balanced_accuracy"]
        return "-" if v is None else f"{v:.2f}"

    ax.set_title(f"{m['n']} PSTs: balanced accuracy {ba('model')} (majority class {ba('majority')}, "
                 f"weac static {ba('weac_static')})", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
