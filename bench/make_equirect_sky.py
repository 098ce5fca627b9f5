#!/usr/bin/env python3
"""Writes a test equirectangular sky as a Radiance .hdr (flat RGBE scanlines, no dependencies).

Row 0 = +Y (zenith), the mapping of docs/cli.md. A blue gradient above the horizon, a dim ground
below, and a small sun (radiance SUN, about 0.5 % of the sphere) 30 degrees above the horizon:
a high-dynamic-range sky whose direct light needs the map's importance sampling.

  bench/make_equirect_sky.py OUT.hdr [WIDTH]
"""
import math
import sys

SUN = (60.0, 50.0, 40.0)


def radiance(u, v):
    theta = v * math.pi
    phi = (u - 0.5) * 2 * math.pi
    if theta < math.pi / 2:
        sun_theta, sun_phi = math.radians(60), math.radians(-70)
        if abs(theta - sun_theta) < 0.06 and abs(phi - sun_phi) < 0.12:
            return SUN
        t = math.cos(theta)  # 1 at the zenith
        return (0.6 - 0.3 * t, 0.75 - 0.2 * t, 1.1)
    return (0.15, 0.12, 0.1)


def rgbe(c):
    m = max(c)
    if m < 1e-32:
        return bytes((0, 0, 0, 0))
    mantissa, exponent = math.frexp(m)
    scale = mantissa * 256.0 / m
    return bytes((int(c[0] * scale), int(c[1] * scale), int(c[2] * scale), exponent + 128))


def main():
    path = sys.argv[1]
    width = int(sys.argv[2]) if len(sys.argv) > 2 else 512
    height = width // 2
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(f"-Y {height} +X {width}\n".encode())
        for y in range(height):
            f.write(b"".join(rgbe(radiance((x + 0.5) / width, (y + 0.5) / height)) for x in range(width)))


if __name__ == "__main__":
    main()
