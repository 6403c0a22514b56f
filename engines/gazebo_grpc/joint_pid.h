// A joint's PID controller with Gazebo's semantics (common::PID): the I term is clamped to
// [IMin, IMax] (so IMax = IMin = 0 disables it), the D term differentiates the error, and
// the output is an effort on the joint.
#pragma once

namespace convoy::world {

class JointPid {
 public:
  JointPid(double p, double i, double d, double i_max, double i_min)
      : p_(p), i_(i), d_(d), i_max_(i_max), i_min_(i_min) {}

  double update(double error, double dt) {  // error = current - target
    double p_term = p_ * error;
    i_err_ += dt * error;
    double i_term = i_ * i_err_;
    if (i_term > i_max_) {
      i_term = i_max_;
      if (i_ != 0) i_err_ = i_term / i_;
    } else if (i_term < i_min_) {
      i_term = i_min_;
      if (i_ != 0) i_err_ = i_term / i_;
    }
    if (dt > 0) {
      d_err_ = (error - last_err_) / dt;
      last_err_ = error;
    }
    return -(p_term + i_term + d_ * d_err_);
  }
  void reset() { i_err_ = d_err_ = last_err_ = 0; }

 private:
  double p_, i_, d_, i_max_, i_min_;
  double i_err_ = 0, d_err_ = 0, last_err_ = 0;
};

}  // namespace convoy::world
