// A Ceres iteration callback that ends a solve, successfully and with its current point, at the
// first iteration where a StopCondition is reached (a deadline, an interrupt).
#ifndef EVFS_SOLVER_STOP_CALLBACK_H_
#define EVFS_SOLVER_STOP_CALLBACK_H_

#include <ceres/iteration_callback.h>

#include "evfs/core/stop_condition.h"

namespace evfs {

class StopCallback : public ceres::IterationCallback {
 public:
  explicit StopCallback(const StopCondition& stop) : stop_(stop) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return stop_.Reached() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  const StopCondition stop_;
};

}  // namespace evfs

#endif  // EVFS_SOLVER_STOP_CALLBACK_H_
