// The ranges of input numbers sigmafem accepts, in SI units. Each bound lies far beyond any
// organ, instrument or material it models, and far enough below double's range (1.8e308) that
// no product the simulation or the filter forms from them (forces, squared residuals, the CG
// stop test tol * |b|) overflows: a finite but absurd input is refused where it is read,
// naming its field, instead of turning into an infinity deep inside a solve.
#pragma once

namespace sigmafem {

// Any number in a scenario (moduli, stiffnesses, gravity, speeds, times, effect values).
// Steel's Young's modulus is 2e11 Pa.
constexpr double kMaxScenarioMagnitude = 1e12;
// A position in metres (observed points, the SO, trajectory waypoints): an operating room
// is a few metres across.
constexpr double kMaxPositionMagnitude = 1e3;
// A measurement noise or observation standard deviation, in metres.
constexpr double kMaxNoiseStd = 1.0;
// time.steps: 1e7 steps of a 10 ms scenario are 28 hours of surgery.
constexpr int kMaxSteps = 10'000'000;
// Points in one point-cloud frame: a depth camera's full frame (640 x 480) is 307200; the
// filter wants hundreds to a few thousand, sampled from it.
constexpr int kMaxCloudPoints = 1'000'000;

}  // namespace sigmafem
