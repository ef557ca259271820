# Independent reference values for tests/survey_inference.rs, computed with R (4.2.2)
# base functions (lm, predict.lm, anova) and smatr's own R code (smatr_funcs.R, copied
# from traitecoevo/smatr, see its header) on the frozen release 1.0.0 table.
# Run from the repository root: Rscript tests/golden/survey.R
source("tests/golden/smatr_funcs.R")
d <- read.csv("dataset/releases/1.0.0/robots.csv", stringsAsFactors = FALSE)
d <- d[d$fit == "true", ]
p <- function(name, v) cat(sprintf("%-40s %s\n", name, paste(sprintf("%.10g", v), collapse = " ")))
lb <- d[d$class == "lower-biped", ]
fb <- d[d$class == "full-biped", ]
x <- log10(lb$leg_length_m); y <- log10(lb$mass_kg)
m <- lm(y ~ x)
pr <- predict(m, data.frame(x = 0), interval = "prediction", level = 0.95)
ci <- predict(m, data.frame(x = 0), interval = "confidence", level = 0.95)
p("lower m~L at L=1: median, PI lo, PI hi", 10^c(pr[1], pr[2], pr[3]))
p("lower m~L at L=1: CI lo, CI hi", 10^c(ci[2], ci[3]))
p("lower m~L Duan smearing", mean(10^residuals(m)))
p("lower m~L slope CI", confint(m)[2, ])
tt <- (coef(m)[2] - 3) / summary(m)$coefficients[2, 2]
p("lower m~L OLS t, p (b = 3)", c(tt, 2 * pt(-abs(tt), df = m$df.residual)))
s <- slope.test(y, x, test.value = 3, method = "SMA")
p("lower m~L SMA slope.test b=3: r, p", c(s$r, s$p))
xf <- log10(fb$leg_length_m); yf <- log10(fb$mass_kg)
mf <- lm(yf ~ xf)
tf <- (coef(mf)[2] - 3) / summary(mf)$coefficients[2, 2]
p("full m~L OLS t, p (b = 3)", c(tf, 2 * pt(-abs(tf), df = mf$df.residual)))
# Common slope among the four classes, mass vs leg length.
X <- log10(d$leg_length_m); Y <- log10(d$mass_kg); G <- d$class
sc <- slope.com(Y, X, G, method = "SMA", tol = 1e-12)
p("4 classes SMA slope.com LR, p, b", c(sc$LR, sc$p, sc$b))
f1 <- anova(lm(Y ~ X + G), lm(Y ~ X * G))
p("4 classes OLS slope F, p", c(f1$F[2], f1$`Pr(>F)`[2]))
f2 <- anova(lm(Y ~ X), lm(Y ~ X + G))
p("4 classes OLS elevation F, p", c(f2$F[2], f2$`Pr(>F)`[2]))
p("4 classes OLS common slope", coef(lm(Y ~ X + G))[2])
# Inverse: leg length of a 30 kg lower biped (median mass on the OLS line).
p("lower L for m=30", 10^((log10(30) - coef(m)[1]) / coef(m)[2]))
# Leave-one-out for `survey fit --explain full-biped`: slope of m ~ L without each robot,
# the robot moving it most, and R² of L_B ~ L without Unitree H1.
loo <- sapply(seq_len(nrow(fb)), function(i) coef(lm(yf[-i] ~ xf[-i]))[2])
k <- which.max(abs(loo - coef(mf)[2]))
cat(sprintf("%-40s %s %.10g\n", "full m~L LOO: top robot, b without", fb$id[k], loo[k]))
h <- fb$id != "unitree-h1"
p("full L_B~L R2 without unitree-h1", summary(lm(log10(fb$body_length_m[h]) ~ log10(fb$leg_length_m[h])))$r.squared)
