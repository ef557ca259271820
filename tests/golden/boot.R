# Expected values of tests/regression_smatr.rs (bca_interval_matches_boot_bca_ci,
# animals_jackknife_influence_matches_boot_empinf). R 4.2.2, boot 1.3-28.1:
#   Rscript tests/golden/boot.R
library(boot)
i <- 1:199
t <- (i / 200)^2 + 0.05 * sin(i)
t0 <- 0.3
L <- cos(1:20) + 0.3 * sin(2 * (1:20))
for (conf in c(0.95, 0.90)) {
  r <- boot:::bca.ci(NULL, conf = conf, t0 = t0, t = t, L = L)
  cat(sprintf("conf %.2f: %.15g %.15g\n", conf, r[1, 4], r[1, 5]))
}
w <- qnorm(sum(t < t0) / length(t)); a <- sum(L^3) / (6 * sum(L^2)^1.5)
cat(sprintf("w %.15g a %.15g\n", w, a))
# Animals jackknife influence of the SMA and MA slopes (empinf type = "jack", stype = "i")
an <- read.csv(text = "x,y
1.35,8.1
465,423
36.33,119.5
27.66,115
1.04,5.5
11700,50
2547,4603
187.1,419
521,655
10,115
3.3,25.6
529,680
207,406
62,1320
6654,5712
9400,70
6.8,179
35,56
0.12,1
0.023,0.4
2.5,12.1
55.5,175
100,157
52.16,440
0.28,1.9
87000,154.5
0.122,3
192,180")
d <- data.frame(x = log10(an$x), y = log10(an$y))
sma <- function(d, i) { v <- cov(d[i, ]); sign(v[1, 2]) * sqrt(v[2, 2] / v[1, 1]) }
ma <- function(d, i) { v <- cov(d[i, ]) * (length(i) - 1); fac <- v[2, 2] - v[1, 1]; (fac + sqrt(fac^2 + 4 * v[1, 2]^2)) / 2 / v[1, 2] }
ols_a <- function(d, i) { coef(lm(y ~ x, data = d[i, ]))[1] }
for (nm in c("sma", "ma", "ols_a")) {
  f <- get(nm)
  L <- empinf(data = d, statistic = f, type = "jack", stype = "i")
  cat(sprintf("%s L1 %.15g L6 %.15g L26 %.15g a %.15g\n", nm, L[1], L[6], L[26], sum(L^3) / (6 * sum(L^2)^1.5)))
}
