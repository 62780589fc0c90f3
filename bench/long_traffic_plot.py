#!/usr/bin/env python3
"""The scaling plot of bench/README.md (issue 45): reads the Markdown table bench/long_traffic.sh
prints (from a file or stdin) and writes an SVG of run time and peak memory against the number of
frames, both axes logarithmic, with the line of proportional cost through the 10-frame point.
Standard library only.

    bash bench/long_traffic.sh build/cli/isolink > t.md && python3 bench/long_traffic_plot.py t.md out.svg
"""
import math
import sys


def rows(text):
    out = []
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 6 or not cells[0].isdigit():
            continue
        out.append((int(cells[0]), float(cells[2]), float(cells[5])))
    return out


def main():
    text = open(sys.argv[1]).read() if len(sys.argv) > 1 and sys.argv[1] != "-" else sys.stdin.read()
    data = rows(text)
    if not data:
        sys.exit("no table rows")
    w, h, left, right, top, bottom = 640, 380, 70, 80, 30, 50
    xs = [math.log10(n) for n, _, _ in data]
    ref = [d for d in data if d[0] == 10] or data[:1]
    n10, s10, _ = ref[0]
    prop = [(math.log10(n), math.log10(s10 * n / n10)) for n, _, _ in data if n >= n10]
    ys = [math.log10(s) for _, s, _ in data] + [math.log10(m / 100) for _, _, m in data]
    ys += [y for _, y in prop]
    x0, x1 = math.floor(min(xs)), math.ceil(max(xs))
    y0, y1 = math.floor(min(ys + [0])), math.ceil(max(ys))

    def px(x):
        return left + (x - x0) / (x1 - x0) * (w - left - right)

    def py(y):
        return h - bottom - (y - y0) / (y1 - y0) * (h - top - bottom)

    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
           f'<rect width="{w}" height="{h}" fill="white"/>']
    for k in range(x0, x1 + 1):
        svg.append(f'<line x1="{px(k):.1f}" y1="{top}" x2="{px(k):.1f}" y2="{h - bottom}" stroke="#ddd"/>')
        svg.append(f'<text x="{px(k):.1f}" y="{h - bottom + 16}" text-anchor="middle">{10 ** k:g}</text>')
    for k in range(y0, y1 + 1):
        svg.append(f'<line x1="{left}" y1="{py(k):.1f}" x2="{w - right}" y2="{py(k):.1f}" stroke="#ddd"/>')
        svg.append(f'<text x="{left - 6}" y="{py(k) + 4:.1f}" text-anchor="end">{10 ** k:g} s</text>')
        svg.append(f'<text x="{w - right + 6}" y="{py(k) + 4:.1f}">{100 * 10 ** k:g} MB</text>')
    svg.append(f'<text x="{w / 2}" y="{h - 12}" text-anchor="middle">frames (stack-write commands, ~0.1 ms each)</text>')

    def line(points, color, dash=""):
        d = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in points)
        svg.append(f'<polyline points="{d}" fill="none" stroke="{color}" stroke-width="2" {dash}/>')
        for x, y in points:
            svg.append(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3" fill="{color}"/>')

    line([(math.log10(n), math.log10(s)) for n, s, _ in data], "#1f3f77")
    line([(math.log10(n), math.log10(m / 100)) for n, _, m in data], "#c05000")
    svg.append('<polyline points="' + " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in prop) +
               '" fill="none" stroke="#888" stroke-dasharray="5,4"/>')
    svg.append(f'<text x="{left + 8}" y="{top + 14}" fill="#1f3f77">isolink run (s, left)</text>')
    svg.append(f'<text x="{left + 8}" y="{top + 30}" fill="#c05000">max RSS (MB, right)</text>')
    svg.append(f'<text x="{left + 8}" y="{top + 46}" fill="#888">time proportional to frames, from 10</text>')
    svg.append("</svg>")
    out = "\n".join(svg) + "\n"
    if len(sys.argv) > 2:
        open(sys.argv[2], "w").write(out)
    else:
        sys.stdout.write(out)


if __name__ == "__main__":
    main()
