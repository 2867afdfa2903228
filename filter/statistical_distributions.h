// The distribution functions the residual diagnostics test against: standard normal,
// chi-square, F, Student's t and binomial tails and quantiles. Written here rather than taken from
// a statistics library because sigmafem needs only these few, in double precision, with
// tails far out (Bonferroni thresholds near 1e-5).
//
// Tails are computed directly (not as 1 - cdf) so that small probabilities keep their
// relative accuracy. Chi-square and t quantiles start from a closed-form approximation
// (Wilson-Hilferty; Cornish-Fisher) and are refined on the exact distribution function
// (regularised incomplete gamma and beta functions), so they are exact to about 1e-10
// relative for every degree of freedom, small ones included.
#pragma once

namespace sigmafem {

// Standard normal: P(Z > z), and the z with P(Z <= z) = probability (Acklam's rational
// approximation with one Halley step on erfc: about 1e-15 relative).
double normal_tail(double z);
double normal_quantile(double probability);

// Regularised incomplete gamma P(a, x) = gamma(a, x) / Gamma(a) and its complement Q.
double regularized_gamma_p(double a, double x);
double regularized_gamma_q(double a, double x);
// Regularised incomplete beta I_x(a, b).
double regularized_beta(double x, double a, double b);

// Chi-square with `dof` degrees of freedom (dof > 0, not necessarily an integer):
// P(X <= x), P(X > x), the x with P(X <= x) = probability, the x with P(X > x) = tail.
double chi_square_cdf(double x, double dof);
double chi_square_tail(double x, double dof);
double chi_square_quantile(double probability, double dof);
double chi_square_tail_quantile(double tail, double dof);

// Chi-bar-square of L: the sum over L independent N(0, 1) variables of max(z, 0)^2, the null
// distribution of a one-sided test on L statistics (only positive deviations count):
// P(X > x) = sum_{j=1..L} C(L, j) 2^-L P(chi^2_j > x) (x > 0), and the x with P(X > x) = tail
// (tail < 1 - 2^-L).
double chi_bar_square_tail(double x, int L);
double chi_bar_square_tail_quantile(double tail, int L);

// Snedecor's F with d1 and d2 degrees of freedom (the ratio of two independent chi-squares,
// each over its degrees of freedom): P(X > x), and the x with P(X > x) = tail.
double f_tail(double x, double d1, double d2);
double f_tail_quantile(double tail, double d1, double d2);

// Student's t with `dof` degrees of freedom: P(|T| > t) and the t > 0 with P(|T| > t) = tail.
double student_t_two_sided_tail(double t, double dof);
double student_t_two_sided_quantile(double tail, double dof);

// Binomial(n, p): P(X >= k).
double binomial_tail(int k, int n, double p);

}  // namespace sigmafem
