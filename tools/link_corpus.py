#!/usr/bin/env python3
"""Seeded random link specs over the whole space a user can describe (issue 28's corpus).

    python3 tools/link_corpus.py --seed 1 --count 300 --out DIR   # DIR/link_000.yaml ...

Every spec is a complete link (both ends, cable, one stack-write each way). The space:
  - devices: tx bq79600 | bq7961x | bq79606a, rx bq7961x | bq79606a (the bridge sits at the base);
  - isolation per end: none, cap (1 / 2.2 / 4.7 / 10 nF), capchoke (one or two chokes of the
    library), transformer (each library transformer), transformer_choke; both ends drawn
    independently, so most links are asymmetric;
  - terminations 1 k or 10 k; X caps (0 or 100 pF - 1 nF) and Y caps (0 or 10 - 470 pF per line);
  - cable 0.1-100 m, log-uniform, with 100 m and 0.1 m always in (the first two specs),
    PP or PVC, every AWG size 18-30, temperature -40..85 degC.
The same seed gives the same files on every machine (Python's random.Random is specified).
"""
import argparse
import math
import os
import random

CHOKES = ["ACT45B-510-2P-TL003", "ACT45B-101-2P-TL003", "744242471"]
TRANSFORMERS = ["HMU1228NL", "HM2147NL", "SM91502AL", "CDEP99-102"]
CAPS = ["1n", "2.2n", "4.7n", "10n"]
GAUGES = [18, 20, 22, 24, 26, 28, 30]


def isolation(rng):
    kind = rng.choice(["none", "cap", "cap", "capchoke", "transformer", "transformer",
                       "transformer_choke"])
    if kind == "none":
        return "{type: none}"
    if kind == "cap":
        return "{type: cap, cap: %s}" % rng.choice(CAPS)
    if kind == "capchoke":
        chokes = rng.sample(CHOKES, rng.choice([1, 2]))
        return "{type: capchoke, cap: %s, chokes: [%s]}" % (rng.choice(CAPS), ", ".join(chokes))
    if kind == "transformer":
        return "{type: transformer, part: %s}" % rng.choice(TRANSFORMERS)
    return "{type: transformer_choke, part: %s, chokes: [%s]}" % (
        rng.choice(TRANSFORMERS), rng.choice(CHOKES))


def end(rng, device):
    parts = ["device: " + device, "termination: " + rng.choice(["1k", "10k"])]
    if rng.random() < 0.25:
        parts.append("x_cap: %dp" % rng.choice([100, 220, 470, 1000]))
    if rng.random() < 0.25:
        parts.append("y_cap: %dp" % rng.choice([10, 47, 100, 470]))
    parts.append("isolation: " + isolation(rng))
    return "{" + ", ".join(parts) + "}"


def spec(rng, index):
    if index == 0:
        length = 100.0
    elif index == 1:
        length = 0.1
    else:
        length = math.exp(rng.uniform(math.log(0.1), math.log(100.0)))
    material = rng.choice(["pp", "pvc"])
    temperature = rng.choice([-40, 25, 25, 85])
    lines = [
        "# tools/link_corpus.py, spec %d" % index,
        "name: corpus-%03d" % index,
        "tx: " + end(rng, rng.choice(["bq79600", "bq7961x", "bq79606a"])),
        "rx: " + end(rng, rng.choice(["bq7961x", "bq79606a"])),
        "cable: {length: %.4g, material: %s, gauge: %d, temperature: %d}"
        % (length, material, rng.choice(GAUGES), temperature),
        'stimulus: {frames: ["stack-write reg=0x0100 data=02B778BC"]}',
    ]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=300)
    ap.add_argument("--first", type=int, default=0, help="index of the first spec written")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rng = random.Random(a.seed)
    for i in range(a.first + a.count):
        text = spec(rng, i)  # drawn in order, so a subset is the same specs as the full corpus
        if i >= a.first:
            with open(os.path.join(a.out, "link_%03d.yaml" % i), "w") as f:
                f.write(text)


if __name__ == "__main__":
    main()
