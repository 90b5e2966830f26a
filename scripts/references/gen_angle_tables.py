#!/usr/bin/env python3
"""Constants and test fixture for the exact angle reduction of crates/rod-ig-core/src/angle.rs.

Prints the Rust table of the bits of 1/(2π) (Payne & Hanek 1983 reduction: 20 words of 64 bits,
enough for the largest f64 exponent plus 192 guard bits) and 2π as a double-double, and writes
crates/rod-ig-core/tests/data/angle_reduction.jsonl: angles and their reduction to (−π, π] in
80-digit arithmetic, rounded to the nearest f64 (mpmath). Run: python3 scripts/references/gen_angle_tables.py
"""
import json, pathlib, random
import mpmath as mp

mp.mp.prec = 1600
inv2pi = 1 / (2 * mp.pi)
bits = int(mp.floor(inv2pi * mp.mpf(2) ** (64 * 20)))
words = [(bits >> (64 * (19 - i))) & ((1 << 64) - 1) for i in range(20)]
print("const INV_TWO_PI_BITS: [u64; 20] = [")
for w in words:
    print(f"    0x{w:016X},")
print("];")
two_pi = 2 * mp.pi
hi = float(two_pi)
lo = float(two_pi - mp.mpf(hi))
print(f"const TWO_PI_HI: f64 = {hi!r};\nconst TWO_PI_LO: f64 = {lo!r};")


def reduce(x):
    r = mp.mpf(x) - two_pi * mp.floor(mp.mpf(x) / two_pi + mp.mpf(1) / 2)
    if r <= -mp.pi:
        r += two_pi
    return float(r)


random.seed(7)
xs = [0.0, 1.0, -1.0, 3.141592653589793, -3.141592653589793, 6.283185307179586, 1e22, -1e22,
      1e300, -1e300, 1.7976931348623157e308, 5e-324, 2.0 ** 53, 710.0, 1e5 * 6.283185307179586]
xs += [random.choice([-1, 1]) * 10 ** random.uniform(-3, 308) for _ in range(400)]
xs += [float(k * two_pi) for k in (1, 3, 7, 1e5, 1e10, 1e15, 6381956970095103, 2 ** 60)]
root = pathlib.Path(__file__).resolve().parents[2]
out = root / "crates" / "rod-ig-core" / "tests" / "data" / "angle_reduction.jsonl"
with out.open("w") as f:
    for x in xs:
        f.write(json.dumps({"x": x, "wrapped": reduce(x)}) + "\n")
