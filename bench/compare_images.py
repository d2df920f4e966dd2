#!/usr/bin/python3
"""compare_images.py -- a rendered image against a converged reference, by luminance.

    bench/compare_images.py REFERENCE.pfm IMAGE.pfm --ids IDS.pfm
                            [--reference2 REF2.pfm] [--margin PX] [--errors ERR.png]

Both images are linear radiance (W/(m^2 sr)) as `radiosity render -o x.pfm` and
bench/pathtrace write them.  An IMAGE whose size is an integer multiple of the
reference's is first averaged over blocks of pixels (a 512 x 512 render against
a 128 x 128 reference: 4 x 4 blocks; both are box-filtered pixel means, so the
block mean is the coarse pixel's mean).

Luminance: Rec. 709 Y = 0.2126 R + 0.7152 G + 0.0722 B.

Interior pixels (IDS: bench/pathtrace's --ids, channel 0 the polygon at the
pixel's centre, channel 1 = 1 where all 4 x 4 strata of the pixel see the same
polygon's front side): a pixel counts when it and every pixel within MARGIN
pixels of it (a square, default 1, so the 3 x 3 neighbourhood) see one and the
same polygon.  So silhouettes, the edges between walls, contact lines (the
blocks on the floor) and the background (misses and back sides: the box's
open front seen past its rim) are left out with a pixel either side, and what
remains are smooth surfaces and the shadows on them, which is what the
comparison is about.

Prints the relative RMS of luminance over the interior pixels,
sqrt(mean(((Y - Y_ref) / Y_ref)^2)), the share of them more than 5% off, and the
mean ratio.  With --reference2 (the same reference made with another seed),
REFERENCE and REF2 are averaged first, and the noise of that average is
estimated from their difference, sigma = RMS((Y1 - Y2) / (Y1 + Y2)) (each
seed's relative noise is RMS((Y1 - Y2) / Ybar) / sqrt 2, the mean of two has
half of that), and the RMS is also given less that noise in quadrature.
"""
import argparse
import sys
import zlib
import struct

import numpy as np

Y_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])


def read_pfm(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            sys.exit("compare_images.py: %s is not an RGB PFM" % path)
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.fromfile(f, "<f4" if scale < 0 else ">f4", count=w * h * 3)
    return data.reshape(h, w, 3)[::-1].astype(np.float64)  # row 0 at the top


def block_mean(image, shape):
    h, w = shape
    H, W = image.shape[:2]
    if H % h or W % w or H // h != W // w:
        sys.exit("compare_images.py: %dx%d is not a multiple of the reference's %dx%d" % (W, H, w, h))
    k = H // h
    return image.reshape(h, k, w, k, -1).mean(axis=(1, 3))


def interior_mask(ids, margin):
    poly, one = ids[:, :, 0], ids[:, :, 1] > 0.5
    ok = one.copy()
    h, w = poly.shape
    for dy in range(-margin, margin + 1):
        for dx in range(-margin, margin + 1):
            shifted_one = np.zeros_like(one)
            shifted_poly = np.full_like(poly, -2.0)
            ys, yd = slice(max(dy, 0), h + min(dy, 0)), slice(max(-dy, 0), h + min(-dy, 0))
            xs, xd = slice(max(dx, 0), w + min(dx, 0)), slice(max(-dx, 0), w + min(-dx, 0))
            shifted_one[yd, xd] = one[ys, xs]
            shifted_poly[yd, xd] = poly[ys, xs]
            ok &= shifted_one & (shifted_poly == poly)
    return ok


def write_error_png(path, rel, mask):
    """Relative error as colour: red too bright, blue too dark, full at +-20%; grey outside."""
    h, w = rel.shape
    t = np.clip(rel / 0.2, -1.0, 1.0)
    rgb = np.empty((h, w, 3))
    rgb[..., 0] = np.where(t > 0, 1.0, 1.0 + t)
    rgb[..., 1] = 1.0 - np.abs(t)
    rgb[..., 2] = np.where(t < 0, 1.0, 1.0 - t)
    rgb[~mask] = 0.5
    rgb8 = (rgb * 255 + 0.5).astype(np.uint8)
    raw = b"".join(b"\0" + rgb8[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("reference")
    ap.add_argument("image")
    ap.add_argument("--ids", required=True)
    ap.add_argument("--reference2")
    ap.add_argument("--margin", type=int, default=1)
    ap.add_argument("--errors", help="write the relative error map as PNG (red: too bright, blue: too dark)")
    a = ap.parse_args()

    ref = read_pfm(a.reference)
    noise = None
    if a.reference2:
        ref2 = read_pfm(a.reference2)
        y1, y2 = ref @ Y_WEIGHTS, ref2 @ Y_WEIGHTS
        ref = 0.5 * (ref + ref2)
    ids = read_pfm(a.ids)
    img = read_pfm(a.image)
    if img.shape != ref.shape:
        img = block_mean(img, ref.shape[:2])
    mask = interior_mask(ids, a.margin)
    y_ref, y_img = ref @ Y_WEIGHTS, img @ Y_WEIGHTS
    mask &= y_ref > 0
    rel = np.zeros_like(y_ref)
    rel[mask] = y_img[mask] / y_ref[mask] - 1.0
    r = rel[mask]
    rms = float(np.sqrt(np.mean(r * r)))
    print("interior pixels: %d of %d (margin %d px)" % (mask.sum(), mask.size, a.margin))
    print("relative RMS of luminance: %.2f%%" % (100 * rms))
    print("pixels beyond 5%%: %.1f%%" % (100 * np.mean(np.abs(r) > 0.05)))
    print("mean luminance ratio (image / reference): %.4f" % (y_img[mask].mean() / y_ref[mask].mean()))
    if a.reference2:
        s = (y1 - y2)[mask] / (y1 + y2)[mask]
        noise = float(np.sqrt(np.mean(s * s)))
        print("reference noise (mean of the two): %.2f%%; RMS less it in quadrature: %.2f%%" %
              (100 * noise, 100 * np.sqrt(max(rms * rms - noise * noise, 0.0))))
    if a.errors:
        write_error_png(a.errors, rel, mask)


if __name__ == "__main__":
    main()
