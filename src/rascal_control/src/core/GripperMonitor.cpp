#include "rascal_control/GripperMonitor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace rascal_control {

GripperMonitor::GripperMonitor(const rascal_workcell::GripperGeometry& gripper, const Settings& settings)
    : gripper_(gripper), settings_(settings) {
  if (!(gripper_.finger_max > gripper_.finger_min)) {
    throw std::invalid_argument("GripperMonitor: finger limits must satisfy min < max (GripperGeometry::fromUrdf)");
  }
}

GripperMonitor::Target GripperMonitor::target(int command, double width) const {
  Target t;
  switch (command) {
    case kOpen:
      width = width == 0.0 ? gripper_.maxOpening() : width;
      break;
    case kClose:
      width = gripper_.minOpening();
      break;
    case kWidth:
      break;
    default:
      t.reason = "unknown gripper command " + std::to_string(command);
      return t;
  }
  if (!(width >= gripper_.minOpening() - 1e-9 && width <= gripper_.maxOpening() + 1e-9)) {
    char text[120];
    std::snprintf(text, sizeof(text), "gripper width %s m is outside [%.3f, %.3f]", std::to_string(width).c_str(),
                  gripper_.minOpening(), gripper_.maxOpening());
    t.reason = text;
    return t;
  }
  t.valid = true;
  t.finger = std::min(gripper_.finger_max, std::max(gripper_.finger_min, gripper_.fingerFor(width)));
  return t;
}

double GripperMonitor::strokeTime(double from, double to) const {
  return settings_.stroke_time * std::fabs(to - from) / (gripper_.finger_max - gripper_.finger_min);
}

void GripperMonitor::addSample(const FingerSample& sample) {
  if (!history_.empty() && sample.t < history_.back().t) {
    history_.clear();  // time went back: the driver (simulator) restarted
    known_ = false;
  }
  history_.push_back(sample);
  // the driver's gap is between the finger joints; the opening is between the pads fitted inside
  history_.back().opening = gripper_.openingAt(sample.opening);
  while (history_.size() > 2 && history_.front().t < sample.t - kHistory) {
    history_.pop_front();
  }
}

void GripperMonitor::start(double finger) {
  if (history_.empty()) {
    throw std::logic_error("GripperMonitor::start: no finger sample yet");
  }
  known_ = true;
  over_ = false;
  target_ = finger;
  from_ = latest().position;
  closing_ = target_ < from_;
}

bool GripperMonitor::stalled(double elapsed, double wall) const {
  const double left = latest().position;
  // Only once the fingers have moved (the command has arrived), or after a full stroke's time.
  const bool moved = std::fabs(left - from_) > kFingerReached;
  // Fast: the driver's finger velocity has been zero for the last few samples.
  if (moved && history_.size() >= kStoppedSamples) {
    bool stopped = true;
    for (auto it = history_.end() - kStoppedSamples; it != history_.end(); ++it) {
      stopped = stopped && std::fabs(it->velocity) < kFingerStopped;  // false for NaN
    }
    if (stopped) {
      return true;
    }
  }
  // Slow: the finger position has not changed over the stall window (of stamps).
  if (elapsed <= 1.5 * kStallWindow) {
    return false;
  }
  const double t_now = latest().t;
  double lo = left, hi = left;
  bool covered = false;
  for (const FingerSample& h : history_) {
    if (h.t >= t_now - kStallWindow) {
      lo = std::min(lo, h.position);
      hi = std::max(hi, h.position);
    } else {
      covered = true;
    }
  }
  const double still_for = settings_.stroke_time + kStallWindow;
  return covered && hi - lo < kFingerStall &&
         (moved ? wall > kStallWindow : elapsed > still_for && wall > still_for);
}

GripperMonitor::Decision GripperMonitor::update(double elapsed, double wall) {
  if (history_.empty()) {
    throw std::logic_error("GripperMonitor::update: no finger sample yet");
  }
  Decision d;
  if (std::fabs(latest().position - target_) < kFingerReached || stalled(elapsed, wall)) {
    over_ = true;
    d.status = Status::Done;
    d.holding = holding();
    char text[96];
    std::snprintf(text, sizeof(text), "opening %.1f mm%s", latest().opening * 1000.0,
                  d.holding ? ", holding an object" : "");
    d.reason = text;
    return d;
  }
  if (elapsed > settings_.timeout && wall > settings_.timeout) {
    over_ = true;
    d.status = Status::Timeout;
    d.reason = "fingers still moving " + std::to_string(elapsed) + " s after the command";
  }
  return d;
}

void GripperMonitor::cancel() {
  over_ = true;
  closing_ = false;
  target_ = history_.empty() ? target_ : latest().position;
}

bool GripperMonitor::holding() const {
  if (history_.empty()) {
    return false;
  }
  const double left = latest().position;
  if (!known_) {
    return left > gripper_.finger_min + settings_.held_margin / 2.0 &&
           left < gripper_.finger_max - settings_.held_margin;
  }
  return closing_ && over_ && left > target_ + settings_.held_margin / 2.0;
}

}  // namespace rascal_control
