// amsa_window.h: control/estimators/window.py's sliding time window, for the C++ estimators.
#pragma once
#include <cstddef>
#include <deque>
#include <utility>

namespace amsa {

// Samples of the last span seconds, oldest first; one at exactly now - span is kept (as the
// Python's, so a 30 s window at 4 Hz holds 121 samples once full).
template <typename T>
class Window {
 public:
  explicit Window(double span = 0.0) : span_(span) {}

  void add(double t, T item) {
    items.emplace_back(t, std::move(item));
    const double limit = t - span_;
    while (!items.empty() && items.front().first < limit) items.pop_front();
  }

  std::size_t size() const { return items.size(); }

  // Seconds between the oldest and newest sample (0 with fewer than two).
  double covered_s() const { return items.size() < 2 ? 0.0 : items.back().first - items.front().first; }

  std::deque<std::pair<double, T>> items;

 private:
  double span_;
};

}  // namespace amsa
