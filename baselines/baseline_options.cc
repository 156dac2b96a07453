#include "evfs/baselines/baseline_options.h"

#include <algorithm>
#include <cmath>

#include "evfs/core/error.h"
#include "evfs/core/option_checker.h"

namespace evfs {

bool BaselineOptions::IsValid(std::string* error) const {
  OptionChecker check;
  check.Require(std::isfinite(contrast_threshold), "contrast_threshold", "finite (<= 0 derives it)")
      .Positive("log_offset", log_offset)
      .NonNegative("blur_sigma_px", blur_sigma_px)
      .Require(cutoff_rad_per_s >= 0.0, "cutoff_rad_per_s", ">= 0 (+infinity allowed)")
      .Positive("threshold_search_min", threshold_search_min)
      .Require(std::isfinite(threshold_search_max) && threshold_search_max > threshold_search_min,
               "threshold_search_max", "finite and > threshold_search_min")
      .NonNegative("edi_tv_weight", edi_tv_weight)
      .Require(edi_edge_window > 0.0 && edi_edge_window <= 1.0, "edi_edge_window", "in (0, 1]")
      .Valid(estimation);
  return check.Passed(error);
}

void CheckContrastThreshold(double contrast_threshold, const char* method) {
  if (!(std::isfinite(contrast_threshold) && contrast_threshold > 0.0)) {
    throw InvalidArgumentError(std::string(method) +
                               ": the contrast threshold must be finite "
                               "and > 0, got " +
                               std::to_string(contrast_threshold));
  }
}

double ToIntegrationDomain(double intensity, IntegrationDomain domain, double log_offset) {
  if (domain == IntegrationDomain::kLinear) return intensity;
  return std::log(std::max(intensity, 0.0) + log_offset);
}

double FromIntegrationDomain(double value, IntegrationDomain domain, double log_offset) {
  if (domain == IntegrationDomain::kLinear) return value;
  return std::exp(value) - log_offset;
}

}  // namespace evfs
