#!/usr/bin/env python3
"""check_svg.py - checks the SVG files `dhcal plot` writes, with a real XML parser.

usage: check_svg.py [--circles N] [--bars N] [--text S]... FILE [[options] FILE]...

Options apply to the FILE that follows them. Every FILE must
  * parse as XML (xml.etree.ElementTree), root {http://www.w3.org/2000/svg}svg;
  * have positive numeric width and height and a viewBox "0 0 width height";
  * carry no NaN or infinity in any attribute, and only finite numbers in the numeric ones;
  * keep every data point (circle not of class "legend") inside the viewBox;
  * label each axis (<g class="axis-x"> / "axis-y") with round numbers: finite, increasing,
    evenly spaced by 1, 2 or 5 times a power of ten, each a multiple of that step.
--circles N: exactly N data points; --bars N: exactly N <rect class="bar">;
--text S: some <text> or <title> holds S (after unescaping).
Exit status 0 when every file passes; otherwise 1 and one line per defect on stderr.
Run by tests/tools/test_dhcal_plot.c when python3 is available.
"""
import math
import re
import sys
import xml.etree.ElementTree as ET

SVG = "{http://www.w3.org/2000/svg}"
NUMERIC = {"x", "y", "cx", "cy", "r", "width", "height", "x1", "y1", "x2", "y2",
           "font-size", "stroke-width", "fill-opacity", "stroke-dasharray", "viewBox",
           "transform"}
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
NONFINITE = re.compile(r"(?i)\b(?:nan|inf(?:inity)?)\b")


def numbers(value):
    """The numbers in an attribute value (transform: the arguments of rotate())."""
    return [float(t) for t in NUMBER.findall(value)]


def check_ticks(group, where, problems):
    values = []
    for t in group.iter(SVG + "text"):
        s = "".join(t.itertext()).strip()
        try:
            v = float(s)
        except ValueError:
            problems.append(f"{where}: tick label {s!r} is not a number")
            return
        if not math.isfinite(v):
            problems.append(f"{where}: tick label {s!r} is not finite")
            return
        values.append(v)
    if len(values) < 2:
        problems.append(f"{where}: {len(values)} tick labels")
        return
    # Labels carry 6 significant digits: compare to that precision.
    tol = 1e-5 * max(abs(v) for v in values)
    steps = [b - a for a, b in zip(values, values[1:])]
    step = float(f"{steps[0]:.5g}")
    if step <= 0 or any(abs(s - step) > 1e-6 * step + tol for s in steps):
        problems.append(f"{where}: ticks {values} not increasing evenly")
        return
    mant = step / 10 ** math.floor(math.log10(step))
    if not any(abs(mant - m) < 1e-6 for m in (1.0, 2.0, 5.0)):
        problems.append(f"{where}: tick step {step!r} is not 1, 2 or 5 times a power of ten")
    for v in values:
        k = v / step
        if abs(k - round(k)) > 1e-4 + tol / step:
            problems.append(f"{where}: tick {v!r} is not a multiple of the step {step!r}")
            return


def check_file(path, circles, bars, texts):
    problems = []
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        return [f"{path}: {e}"]
    if root.tag != SVG + "svg":
        problems.append(f"{path}: root is {root.tag}, not an SVG svg element")
    try:
        w = float(root.get("width"))
        h = float(root.get("height"))
        vb = [float(v) for v in root.get("viewBox").split()]
    except (TypeError, ValueError, AttributeError):
        return problems + [f"{path}: width, height or viewBox missing or not numeric"]
    if not (w > 0 and h > 0 and math.isfinite(w) and math.isfinite(h)):
        problems.append(f"{path}: size {w} x {h}")
    if vb != [0.0, 0.0, w, h]:
        problems.append(f"{path}: viewBox {vb} is not 0 0 {w} {h}")

    n_circles = 0
    n_bars = 0
    for el in root.iter():
        for name, value in el.attrib.items():
            if NONFINITE.search(value):
                problems.append(f"{path}: <{el.tag[len(SVG):]} {name}=\"{value}\">: not finite")
            elif name in NUMERIC:
                if not numbers(value) or not all(math.isfinite(v) for v in numbers(value)):
                    problems.append(f"{path}: <{el.tag[len(SVG):]} {name}=\"{value}\">: not a number")
        if el.tag == SVG + "circle" and el.get("class") != "legend":
            n_circles += 1
            cx, cy = float(el.get("cx")), float(el.get("cy"))
            if not (0 <= cx <= w and 0 <= cy <= h):
                problems.append(f"{path}: point ({cx}, {cy}) outside the picture")
        if el.tag == SVG + "rect" and el.get("class") == "bar":
            n_bars += 1
        if el.tag == SVG + "g" and (el.get("class") or "").startswith("axis-"):
            check_ticks(el, f"{path}: {el.get('class')}", problems)
    if circles is not None and n_circles != circles:
        problems.append(f"{path}: {n_circles} data points, expected {circles}")
    if bars is not None and n_bars != bars:
        problems.append(f"{path}: {n_bars} bars, expected {bars}")
    shown = ["".join(el.itertext()) for el in root.iter()
             if el.tag in (SVG + "text", SVG + "title")]
    for t in texts:
        if not any(t in s for s in shown):
            problems.append(f"{path}: no text contains {t!r}")
    return problems


def main(argv):
    problems = []
    circles = bars = None
    texts = []
    n_files = 0
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("--circles", "--bars", "--text"):
            if i + 1 >= len(argv):
                print(f"check_svg.py: {a} needs a value", file=sys.stderr)
                return 2
            if a == "--circles":
                circles = int(argv[i + 1])
            elif a == "--bars":
                bars = int(argv[i + 1])
            else:
                texts.append(argv[i + 1])
            i += 2
            continue
        problems += check_file(a, circles, bars, texts)
        n_files += 1
        circles = bars = None
        texts = []
        i += 1
    if n_files == 0:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    for p in problems:
        print(p, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
