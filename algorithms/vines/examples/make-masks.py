#!/usr/bin/python3
"""Writes the example inclusion maps beside this script (run with Debian's /usr/bin/python3).

spot-body.png   red over spot's body (the right half of its texture), a green dot on each side of the body: vines on
                the body, none on the head, hooves or udder.
lettering.png   the word "vines" in red, with a green dot in each letter's part (the seed's Figure 12,
                inclusion mode writing text), for space=canvas.
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
RED, GREEN, WHITE = (0.9, 0.08, 0.08, 1.0), (0.08, 0.9, 0.08, 1.0), (1.0, 1.0, 1.0, 1.0)


def save(name, rgba):
    plt.imsave(os.path.join(HERE, name), np.clip(rgba, 0, 1))


def dot(img, u, v, r=2):
    """A green dot at UV (u, v) (v up, row 0 at the top)."""
    h, w = img.shape[:2]
    x, y = int(u * w), int((1 - v) * h)
    img[max(y - r, 0):y + r + 1, max(x - r, 0):x + r + 1] = GREEN


def spot_body(size=256):
    img = np.ones((size, size, 4))
    img[:, size // 2:] = RED  # u >= 0.5: the two body sides and the belly
    dot(img, 0.62, 0.72)      # on one side of the body
    dot(img, 0.62, 0.30)      # and on the other
    save("spot-body.png", img)


def components(mask):
    """4-connected components of a boolean image, as lists of (y, x)."""
    seen = np.zeros_like(mask, dtype=bool)
    out = []
    for y0, x0 in zip(*np.nonzero(mask)):
        if seen[y0, x0]:
            continue
        seen[y0, x0] = True
        stack, comp = [(y0, x0)], []
        while stack:
            y, x = stack.pop()
            comp.append((y, x))
            for dy, dx in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                ny, nx = y + dy, x + dx
                if 0 <= ny < mask.shape[0] and 0 <= nx < mask.shape[1] and mask[ny, nx] and not seen[ny, nx]:
                    seen[ny, nx] = True
                    stack.append((ny, nx))
        out.append(comp)
    return out


def lettering(size=512):
    fig = plt.figure(figsize=(size / 100, size / 100), dpi=100)
    fig.text(0.5, 0.5, "vines", ha="center", va="center", fontsize=118, fontweight="bold", family="DejaVu Sans")
    fig.canvas.draw()
    grey = np.asarray(fig.canvas.buffer_rgba())[:, :, 0] < 128
    plt.close(fig)
    img = np.ones((size, size, 4))
    img[grey] = RED
    for comp in components(grey):
        if len(comp) < 30:
            continue
        ys, xs = np.array(comp).T
        # The letter's pixel nearest its centroid (a dot inside it, even for a curved letter).
        k = np.argmin((ys - ys.mean()) ** 2 + (xs - xs.mean()) ** 2)
        dot(img, (xs[k] + 0.5) / size, 1 - (ys[k] + 0.5) / size, r=1)
    save("lettering.png", img)


if __name__ == "__main__":
    spot_body()
    lettering()
