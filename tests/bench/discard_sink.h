// A raster sink for benchmarks: takes the rows and keeps a checksum (no disk in the measurement).
#pragma once

#include "stitch/resample/raster.h"

#include <cstdint>

namespace aerocal::stitch {

class DiscardSink : public RasterSink {
 public:
  explicit DiscardSink(size_t row_bytes) : row_bytes_(row_bytes) {}
  void WriteRows(int, int rows, const void* data) override {
    checksum_ += static_cast<const std::uint8_t*>(data)[rows * row_bytes_ / 2];
  }
  std::uint64_t checksum_ = 0;

 private:
  size_t row_bytes_;
};

}  // namespace aerocal::stitch
