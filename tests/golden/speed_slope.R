# The speed slope tests of tests/it/speed.rs with smatr's own code (smatr_funcs.R, copied
# from traitecoevo/smatr, see its header): the hand-made table of four robots at leg lengths
# 0.005, 0.05, 0.5 and 5 m with speeds v = 10^(0.3 + 0.5 log10 L + e), e = +-0.1.
# The numbers committed in tests/it/speed.rs were computed by speed_slope.py (the same
# formulas in Python with mpmath), R not being reachable where they were made; run this
# where R is, from the repository root, to check them: Rscript tests/golden/speed_slope.R
source("tests/golden/smatr_funcs.R")
L <- c(0.005, 0.05, 0.5, 5)
x <- log10(L)
y <- 0.3 + 0.5 * x + c(0.1, -0.1, -0.1, 0.1)
for (method in c("OLS", "SMA", "MA")) {
  for (b0 in c(0.5, 0.25, 0)) {
    s <- slope.test(y, x, test.value = b0, method = method)
    cat(sprintf("%-4s b0 = %-5s b = %.15g r = %.15g F = %.15g p = %.15g\n",
                method, b0, s$b, s$r, s$F, s$p))
  }
}
# OLS line and its 95% interval (confint of lm), and R's t quantile for the hand check.
m <- lm(y ~ x)
print(confint(m)[2, ], digits = 15)
print(qt(0.975, 2), digits = 15)
