"""Expected numbers of the speed slope tests (tests/it/speed.rs), computed without R.

R and CRAN are not reachable on the machine these goldens were made on, so smatr's own
`slope.test` (tests/golden/smatr_funcs.R, copied from traitecoevo/smatr) was re-implemented
here line by line in Python with mpmath at 50 digits; `speed_slope.R` is the R command that
computes the same numbers with smatr's code, to re-check them where R is available.

The data: the hand-made table of tests/it/speed.rs, four robots at leg lengths 0.005, 0.05,
0.5 and 5 m whose speeds are v = 10^(0.3 + 0.5 log10 L + e) with e = +0.1, -0.1, -0.1, +0.1,
so that the OLS slope is exactly 0.5 (the residual pattern is orthogonal to log10 L).

Run: python3 tests/golden/speed_slope.py   (needs mpmath)
"""

from mpmath import mp, mpf, log10, sqrt, betainc

mp.dps = 50

L = [mpf("0.005"), mpf("0.05"), mpf("0.5"), mpf("5")]
E = [mpf("0.1"), mpf("-0.1"), mpf("-0.1"), mpf("0.1")]
x = [log10(l) for l in L]
y = [mpf("0.3") + mpf("0.5") * xi + e for xi, e in zip(x, E)]


def pf_upper(F, d1, d2):
    """1 - pf(F, d1, d2): the upper tail of the F distribution (regularized incomplete beta)."""
    z = d1 * F / (d1 * F + d2)
    return 1 - betainc(mpf(d1) / 2, mpf(d2) / 2, 0, z, regularized=True)


def slope_test(y, x, test_value, method):
    """smatr slope.test (non-robust branch), as in tests/golden/smatr_funcs.R."""
    n = len(x)
    my, mx = sum(y) / n, sum(x) / n
    # vr <- cov(dat) * (n - 1): sums of squares and products about the means
    vyy = sum((a - my) ** 2 for a in y)
    vxx = sum((b - mx) ** 2 for b in x)
    vxy = sum((a - my) * (b - mx) for a, b in zip(y, x))
    t = mpf(test_value)
    if method == "OLS":
        b = vxy / vxx
        v11 = vyy - 2 * t * vxy + t**2 * vxx
        v12 = vxy - t * vxx
        v22 = vxx
    elif method == "SMA":
        b = (1 if vxy > 0 else -1) * sqrt(vyy / vxx)
        v11 = vyy - 2 * t * vxy + t**2 * vxx
        v12 = vyy - t**2 * vxx
        v22 = vyy + 2 * t * vxy + t**2 * vxx
    else:  # MA
        fac = vyy - vxx
        b = (fac + sqrt(fac**2 + 4 * vxy**2)) / 2 / vxy
        v11 = vyy - 2 * t * vxy + t**2 * vxx
        v12 = -(t**2) * vxy + t * (vyy - vxx) + vxy
        v22 = t**2 * vyy + 2 * t * vxy + vxx
    r = v12 / sqrt(v11) / sqrt(v22)
    F = r**2 / (1 - r**2) * (n - 2)
    return b, r, F, pf_upper(F, 1, n - 2)


if __name__ == "__main__":
    for method in ["OLS", "SMA", "MA"]:
        for tv in ["0.5", "0.25", "0"]:
            b, r, F, p = slope_test(y, x, tv, method)
            print(f"{method:<4} b0 = {tv:<5} b = {mp.nstr(b, 17):<22} r = {mp.nstr(r, 17):<24} F = {mp.nstr(F, 17):<24} p = {mp.nstr(p, 17)}")
