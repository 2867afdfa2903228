#include "filter/statistical_distributions.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sigmafem {
namespace {

constexpr double kEpsilon = 1e-15;           // series and continued fractions stop here
constexpr double kTiny = 1e-300;             // Lentz's guard against a zero denominator
constexpr int kMaxTerms = 10000;
constexpr double kPi = 3.14159265358979323846;

void require(bool condition, const char* function, const std::string& what) {
  if (!condition) throw std::invalid_argument(std::string(function) + ": " + what);
}

// P(a, x) by its power series; converges fast for x < a + 1.
double gamma_p_series(double a, double x) {
  double term = 1.0 / a, sum = term, ap = a;
  for (int n = 0; n < kMaxTerms; ++n) {
    ap += 1.0;
    term *= x / ap;
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * kEpsilon) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) by its continued fraction (modified Lentz); converges fast for x >= a + 1.
double gamma_q_fraction(double a, double x) {
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < kMaxTerms; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEpsilon) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// The continued fraction of I_x(a, b) (modified Lentz); converges fast for x < (a+1)/(a+b+2).
double beta_fraction(double x, double a, double b) {
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0, d = 1.0 - qab * x / qap;
  if (std::fabs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m < kMaxTerms; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));   // even step
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));  // odd step
    d = 1.0 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < kEpsilon) break;
  }
  return h;
}

// The root of tail(x) = target for a function decreasing in x > 0 (tail(0) > target, and
// tail(x) < target for some large x), with density(x) = -tail'(x) > 0: safeguarded Newton from `start`, bisection when Newton
// leaves the bracket.
template <typename Tail, typename Density>
double solve_tail(Tail tail, Density density, double target, double start) {
  double lo = 0.0, hi = std::max(start, 1.0);
  while (tail(hi) > target) {
    lo = hi;
    hi *= 2.0;
    if (hi > 1e300) return std::numeric_limits<double>::infinity();
  }
  double x = (start > lo && start < hi) ? start : 0.5 * (lo + hi);
  for (int i = 0; i < 200; ++i) {
    const double g = tail(x) - target;   // > 0: x is left of the root
    if (g > 0.0) lo = x; else hi = x;
    const double f = density(x);
    double next = (f > 0.0 && std::isfinite(f)) ? x + g / f : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::fabs(next - x) <= 1e-14 * std::fabs(x) || hi - lo <= 1e-14 * hi) return next;
    x = next;
  }
  return x;
}

double chi_square_density(double x, double dof) {
  if (x <= 0.0) return dof < 2.0 ? std::numeric_limits<double>::infinity() : (dof == 2.0 ? 0.5 : 0.0);
  const double k = 0.5 * dof;
  return std::exp((k - 1.0) * std::log(x) - 0.5 * x - k * std::log(2.0) - std::lgamma(k));
}

double f_density(double x, double d1, double d2) {
  if (x <= 0.0) return 0.0;
  const double a = 0.5 * d1, b = 0.5 * d2;
  return std::exp(a * std::log(d1) + b * std::log(d2) + (a - 1.0) * std::log(x) -
                  (a + b) * std::log(d1 * x + d2) - std::lgamma(a) - std::lgamma(b) + std::lgamma(a + b));
}

// Wilson-Hilferty: (X/k)^(1/3) is nearly normal with mean 1 - 2/(9k) and variance 2/(9k).
double wilson_hilferty(double upper_z, double dof) {
  const double a = 2.0 / (9.0 * dof);
  const double cube = 1.0 - a + upper_z * std::sqrt(a);
  return cube > 0.0 ? dof * cube * cube * cube : 0.0;
}

}  // namespace

double normal_tail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

double normal_quantile(double probability) {
  require(probability > 0.0 && probability < 1.0, "normal_quantile", "probability must be in (0, 1)");
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01,  -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  constexpr double low = 0.02425;
  auto tail_formula = [&](double p) {   // the lower-tail branch, p < low
    const double q = std::sqrt(-2.0 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  };
  double x;
  if (probability < low) {
    x = tail_formula(probability);
  } else if (probability > 1.0 - low) {
    x = -tail_formula(1.0 - probability);
  } else {
    const double q = probability - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  // One Halley step on the exact cdf (erfc) takes Acklam's 1e-9 to rounding.
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - probability;
  const double u = e * std::sqrt(2.0 * kPi) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

double regularized_gamma_p(double a, double x) {
  require(a > 0.0 && x >= 0.0, "regularized_gamma_p", "needs a > 0 and x >= 0");
  if (x == 0.0) return 0.0;
  return x < a + 1.0 ? gamma_p_series(a, x) : 1.0 - gamma_q_fraction(a, x);
}

double regularized_gamma_q(double a, double x) {
  require(a > 0.0 && x >= 0.0, "regularized_gamma_q", "needs a > 0 and x >= 0");
  if (x == 0.0) return 1.0;
  return x < a + 1.0 ? 1.0 - gamma_p_series(a, x) : gamma_q_fraction(a, x);
}

double regularized_beta(double x, double a, double b) {
  require(a > 0.0 && b > 0.0 && x >= 0.0 && x <= 1.0, "regularized_beta",
          "needs a > 0, b > 0 and 0 <= x <= 1");
  if (x == 0.0 || x == 1.0) return x;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_fraction(x, a, b) / a;
  return 1.0 - front * beta_fraction(1.0 - x, b, a) / b;
}

double chi_square_cdf(double x, double dof) {
  require(dof > 0.0, "chi_square_cdf", "dof must be positive");
  return x <= 0.0 ? 0.0 : regularized_gamma_p(0.5 * dof, 0.5 * x);
}

double chi_square_tail(double x, double dof) {
  require(dof > 0.0, "chi_square_tail", "dof must be positive");
  return x <= 0.0 ? 1.0 : regularized_gamma_q(0.5 * dof, 0.5 * x);
}

double chi_square_tail_quantile(double tail, double dof) {
  require(dof > 0.0, "chi_square_tail_quantile", "dof must be positive");
  require(tail > 0.0 && tail < 1.0, "chi_square_tail_quantile", "tail must be in (0, 1)");
  const double start = wilson_hilferty(tail < 0.5 ? -normal_quantile(tail) : normal_quantile(1.0 - tail), dof);
  return solve_tail([dof](double x) { return chi_square_tail(x, dof); },
                    [dof](double x) { return chi_square_density(x, dof); }, tail, start);
}

double chi_square_quantile(double probability, double dof) {
  require(probability > 0.0 && probability < 1.0, "chi_square_quantile",
          "probability must be in (0, 1)");
  if (probability >= 0.5) return chi_square_tail_quantile(1.0 - probability, dof);   // 1 - p exact here
  // Lower tail: solve P(X <= x) = probability on the cdf itself (from the series, accurate
  // relative to a small probability), written as the decreasing -cdf for the solver.
  const double start = wilson_hilferty(normal_quantile(probability), dof);
  return solve_tail([dof](double x) { return -chi_square_cdf(x, dof); },
                    [dof](double x) { return chi_square_density(x, dof); }, -probability,
                    start > 0.0 ? start : 1e-3 * dof);
}

double chi_bar_square_tail(double x, int L) {
  require(L > 0, "chi_bar_square_tail", "L must be positive");
  if (x < 0.0) return 1.0;
  if (x == 0.0) return 1.0 - std::ldexp(1.0, -L);   // all L at or below zero: P = 2^-L
  double sum = 0.0, weight = std::ldexp(1.0, -L);   // C(L, j) 2^-L, from j = 0
  for (int j = 1; j <= L; ++j) {
    weight *= static_cast<double>(L - j + 1) / j;
    sum += weight * chi_square_tail(x, j);
  }
  return sum;
}

double chi_bar_square_tail_quantile(double tail, int L) {
  require(L > 0, "chi_bar_square_tail_quantile", "L must be positive");
  require(tail > 0.0 && tail < 1.0 - std::ldexp(1.0, -L), "chi_bar_square_tail_quantile",
          "tail must be in (0, 1 - 2^-L)");
  // The tail decreases in x and lies between the chi-square(1)'s and the chi-square(L)'s.
  double low = 0.0, high = chi_square_tail_quantile(tail, L);
  for (int i = 0; i < 200 && high - low > 1e-12 * high; ++i) {
    const double mid = 0.5 * (low + high);
    (chi_bar_square_tail(mid, L) > tail ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

double f_tail(double x, double d1, double d2) {
  require(d1 > 0.0 && d2 > 0.0, "f_tail", "the degrees of freedom must be positive");
  if (x <= 0.0) return 1.0;
  // P(F > x) = I_{d2 / (d2 + d1 x)}(d2 / 2, d1 / 2): small for large x, computed directly.
  return regularized_beta(d2 / (d2 + d1 * x), 0.5 * d2, 0.5 * d1);
}

double f_tail_quantile(double tail, double d1, double d2) {
  require(d1 > 0.0 && d2 > 0.0, "f_tail_quantile", "the degrees of freedom must be positive");
  require(tail > 0.0 && tail < 1.0, "f_tail_quantile", "tail must be in (0, 1)");
  // log F is nearly normal with variance 2/d1 + 2/d2 for large d: the start.
  const double start = std::exp(normal_quantile(1.0 - tail) * std::sqrt(2.0 / d1 + 2.0 / d2));
  return solve_tail([d1, d2](double x) { return f_tail(x, d1, d2); },
                    [d1, d2](double x) { return f_density(x, d1, d2); }, tail, start);
}

double student_t_two_sided_tail(double t, double dof) {
  require(dof > 0.0, "student_t_two_sided_tail", "dof must be positive");
  t = std::fabs(t);
  return regularized_beta(dof / (dof + t * t), 0.5 * dof, 0.5);
}

double student_t_two_sided_quantile(double tail, double dof) {
  require(dof > 0.0, "student_t_two_sided_quantile", "dof must be positive");
  require(tail > 0.0 && tail < 1.0, "student_t_two_sided_quantile", "tail must be in (0, 1)");
  // Cornish-Fisher expansion of t in z and 1/dof: a start within a few percent for dof >= 5.
  const double z = -normal_quantile(0.5 * tail), z2 = z * z;
  const double start = z + z * (z2 + 1.0) / (4.0 * dof) +
                       z * ((5.0 * z2 + 16.0) * z2 + 3.0) / (96.0 * dof * dof);
  const double log_norm = std::lgamma(0.5 * (dof + 1.0)) - std::lgamma(0.5 * dof) - 0.5 * std::log(dof * kPi);
  return solve_tail([dof](double t) { return student_t_two_sided_tail(t, dof); },
                    [dof, log_norm](double t) {   // density of |T|
                      return 2.0 * std::exp(log_norm - 0.5 * (dof + 1.0) * std::log1p(t * t / dof));
                    },
                    tail, start);
}

double binomial_tail(int k, int n, double p) {
  require(n >= 0 && p >= 0.0 && p <= 1.0, "binomial_tail", "needs n >= 0 and 0 <= p <= 1");
  if (k <= 0) return 1.0;
  if (k > n) return 0.0;
  return regularized_beta(p, k, n - k + 1.0);   // P(X >= k) = I_p(k, n - k + 1)
}

}  // namespace sigmafem
