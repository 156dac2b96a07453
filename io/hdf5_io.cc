#include "evfs/io/hdf5_io.h"

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

#include "evfs/core/error.h"
#include "evfs/core/time.h"
#include "evfs/io/frame_list.h"
#include "evfs/io/image_io.h"
#include "evfs/io/message_excerpt.h"

namespace evfs {
namespace {

// Events are read in blocks of this many so that a whole-file read or summary never holds
// more than one block of conversion buffers.
constexpr int64_t kEventBlock = 1 << 20;
constexpr char kEventsGroup[] = "events";
constexpr char kImagesGroup[] = "images";
constexpr char kSensorResolution[] = "sensor_resolution";
constexpr char kTimestamp[] = "timestamp";
constexpr char kExposureStart[] = "exposure_start";
constexpr char kExposureEnd[] = "exposure_end";
constexpr char kPath[] = "path";
constexpr char kTsUnit[] = "ts_unit";
// Root attribute naming the writer: only a file carrying it may be replaced by `evfs convert`.
constexpr char kWrittenBy[] = "written_by";
constexpr char kEvfs[] = "evfs";
// Image dataset names appear in error messages, which must stay one short line; tools write
// names like image000000000.
constexpr size_t kMaxImageNameBytes = 64;
// Event coordinates are uint16, so no sensor side is longer.
constexpr hsize_t kMaxImageSide = 65536;
// |t| below this many seconds converts to and from int64 nanoseconds without loss.
constexpr double kMaxSeconds = 9.2e9;

// While alive, libhdf5 prints no error stack to stderr (evfs reports its own InputError
// instead); the handler installed before, if any, is restored after, so that other code in the
// process using libhdf5 keeps its own reporting.
class ScopedHdf5ErrorsSilenced {
 public:
  ScopedHdf5ErrorsSilenced()
      : restore_(H5Eget_auto2(H5E_DEFAULT, &previous_, &previous_data_) >= 0) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~ScopedHdf5ErrorsSilenced() {
    if (restore_) H5Eset_auto2(H5E_DEFAULT, previous_, previous_data_);
  }
  ScopedHdf5ErrorsSilenced(const ScopedHdf5ErrorsSilenced&) = delete;
  ScopedHdf5ErrorsSilenced& operator=(const ScopedHdf5ErrorsSilenced&) = delete;

 private:
  H5E_auto2_t previous_ = nullptr;
  void* previous_data_ = nullptr;
  bool restore_;
};

// Around every stretch of libhdf5 calls reading a file the user gave: errors silenced, and a
// crash counted as the file's (core/input_library.h).
class ReadingWithLibhdf5 {
 private:
  ScopedHdf5ErrorsSilenced silenced_;
  ScopedInputLibraryRead reading_{kLibhdf5};
};

// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  ~Handle() { Reset(); }
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, -1)), close_(other.close_) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      Reset();
      id_ = std::exchange(other.id_, -1);
      close_ = other.close_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }

 private:
  void Reset() {
    if (id_ >= 0) {
      const ScopedHdf5ErrorsSilenced silenced;
      close_(id_);
    }
    id_ = -1;
  }

  hid_t id_ = -1;
  Closer close_ = nullptr;
};

// Calls into HDF5 for one file, turning every failure into an InputError naming the file and
// the object involved.
class H5Context {
 public:
  H5Context(std::string path, InputError::Kind failure_kind)
      : path_(std::move(path)), failure_kind_(failure_kind) {}

  const std::string& path() const { return path_; }

  [[noreturn]] void Fail(InputError::Kind kind, const std::string& what) const {
    throw InputError(kind, path_, 0, what);
  }
  Handle Check(hid_t id, Handle::Closer close, const std::string& what) const {
    if (id < 0) Fail(failure_kind_, what);
    return Handle(id, close);
  }
  void CheckStatus(herr_t status, const std::string& what) const {
    if (status < 0) Fail(failure_kind_, what);
  }

 private:
  std::string path_;
  InputError::Kind failure_kind_;
};

// ---------------------------------------------------------------------------------------------
// Reading helpers.

bool HasAttribute(hid_t object, const char* name) { return H5Aexists(object, name) > 0; }

double ReadDoubleAttribute(const H5Context& h5, hid_t object, const char* name,
                           const std::string& where) {
  const std::string what = where + " attribute '" + name + "'";
  const Handle attribute =
      h5.Check(H5Aopen(object, name, H5P_DEFAULT), H5Aclose, "missing " + what);
  const Handle space = h5.Check(H5Aget_space(attribute.get()), H5Sclose, "unreadable " + what);
  if (H5Sget_simple_extent_npoints(space.get()) != 1)
    h5.Fail(InputError::Kind::kMalformed, what + " must hold one number");
  double value = 0.0;
  h5.CheckStatus(H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &value),
                 "unreadable " + what + " (expected a number)");
  if (!std::isfinite(value) || std::fabs(value) >= kMaxSeconds) {
    h5.Fail(InputError::Kind::kOutOfRange, what + " is not a finite time in seconds");
  }
  return value;
}

std::string ReadStringAttribute(const H5Context& h5, hid_t object, const char* name,
                                const std::string& where) {
  const std::string what = where + " attribute '" + name + "'";
  const Handle attribute =
      h5.Check(H5Aopen(object, name, H5P_DEFAULT), H5Aclose, "missing " + what);
  const Handle type = h5.Check(H5Aget_type(attribute.get()), H5Tclose, "unreadable " + what);
  if (H5Tget_class(type.get()) != H5T_STRING)
    h5.Fail(InputError::Kind::kMalformed, what + " must be a string");
  const Handle memory_type = h5.Check(H5Tcopy(H5T_C_S1), H5Tclose, "cannot read " + what);
  if (H5Tis_variable_str(type.get()) > 0) {
    h5.CheckStatus(H5Tset_size(memory_type.get(), H5T_VARIABLE), "cannot read " + what);
    char* value = nullptr;
    h5.CheckStatus(H5Aread(attribute.get(), memory_type.get(), &value), "unreadable " + what);
    std::string result = value != nullptr ? value : "";
    H5free_memory(value);
    return result;
  }
  // One more byte than stored, so that a string filling its whole width still gets its NUL.
  const size_t size = H5Tget_size(type.get()) + 1;
  h5.CheckStatus(H5Tset_size(memory_type.get(), size), "cannot read " + what);
  std::string buffer(size, '\0');
  h5.CheckStatus(H5Aread(attribute.get(), memory_type.get(), &buffer[0]), "unreadable " + what);
  return std::string(buffer.c_str());
}

// Dimensions of a dataset's dataspace.
std::vector<hsize_t> Dimensions(const H5Context& h5, hid_t dataset, const std::string& name) {
  const Handle space = h5.Check(H5Dget_space(dataset), H5Sclose, "unreadable dataspace of " + name);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) h5.Fail(InputError::Kind::kMalformed, "unreadable dataspace of " + name);
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

// HDF5 reads fill values wherever a dataset's storage was never written, so a file whose writer
// stopped early would read as zeros, and a corrupt extent could claim terabytes of them. Throws
// unless the file stores what `dataset` (of extent `dims`) declares: some data at all, and all
// of it when it is not compressed (a compressed size says nothing about the extent).
//
// Also throws for a number type whose bits do not fit in its bytes (precision + bit offset >
// 8 · size): libhdf5 converts such values differently depending on where a read starts, so one
// element would read as two values (the HDF5 fuzzer found an x of 32768 that read as 0 from a
// later start).
void CheckStored(const H5Context& h5, hid_t dataset, const std::string& name,
                 const std::vector<hsize_t>& dims) {
  const Handle type = h5.Check(H5Dget_type(dataset), H5Tclose, "unreadable type of " + name);
  const Handle properties =
      h5.Check(H5Dget_create_plist(dataset), H5Pclose, "unreadable properties of " + name);
  const size_t value_bytes = H5Tget_size(type.get());
  if (value_bytes == 0) h5.Fail(InputError::Kind::kMalformed, "unreadable type of " + name);
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class == H5T_INTEGER || type_class == H5T_FLOAT) {
    const size_t precision = H5Tget_precision(type.get());
    const int offset = H5Tget_offset(type.get());
    if (precision == 0 || offset < 0 || precision + static_cast<size_t>(offset) > 8 * value_bytes) {
      h5.Fail(InputError::Kind::kMalformed, "corrupt type of " + name + ": " +
                                                std::to_string(precision) + " bits at bit offset " +
                                                std::to_string(offset) + " do not fit in " +
                                                std::to_string(value_bytes) + " bytes");
    }
  }
  // In long double: a corrupt extent can overflow 64 bits.
  long double declared_bytes = static_cast<long double>(value_bytes);
  for (const hsize_t dim : dims) declared_bytes *= static_cast<long double>(dim);
  if (declared_bytes == 0) return;
  const hsize_t stored_bytes = H5Dget_storage_size(dataset);
  const bool compressed = H5Pget_nfilters(properties.get()) > 0;
  if (stored_bytes == 0 || (!compressed && stored_bytes < declared_bytes)) {
    std::string extent;
    for (const hsize_t dim : dims) extent += (extent.empty() ? "" : "x") + std::to_string(dim);
    h5.Fail(InputError::Kind::kMalformed,
            name + " declares " + extent + " " + std::to_string(H5Tget_size(type.get())) +
                "-byte values but the file stores " + std::to_string(stored_bytes) +
                " bytes of them (truncated or incomplete file?)");
  }
}

// Reads elements [first, first + count) of a 1-D dataset, converted to `memory_type`.
void ReadSlab(const H5Context& h5, hid_t dataset, const std::string& name, hid_t memory_type,
              int64_t first, int64_t count, void* out) {
  if (count <= 0) return;
  const hsize_t offset = static_cast<hsize_t>(first);
  const hsize_t size = static_cast<hsize_t>(count);
  const std::string what = "cannot read " + name + " [" + std::to_string(first) + ", " +
                           std::to_string(first + count) + ")";
  const Handle file_space = h5.Check(H5Dget_space(dataset), H5Sclose, what);
  h5.CheckStatus(
      H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &offset, nullptr, &size, nullptr),
      what);
  const Handle memory_space = h5.Check(H5Screate_simple(1, &size, nullptr), H5Sclose, what);
  h5.CheckStatus(
      H5Dread(dataset, memory_type, memory_space.get(), file_space.get(), H5P_DEFAULT, out), what);
}

}  // namespace

const InputLibrary kLibhdf5 = {"libhdf5", "some corrupt HDF5 files"};

// ---------------------------------------------------------------------------------------------

class Hdf5DataSource::File {
 public:
  explicit File(const std::string& path) : h5_(path, InputError::Kind::kMalformed) {
    std::error_code error;
    if (!std::filesystem::exists(path, error)) {
      h5_.Fail(InputError::Kind::kMissingFile, "HDF5 file does not exist");
    }
    if (!std::filesystem::is_regular_file(path, error)) {
      h5_.Fail(InputError::Kind::kMalformed,
               "not a regular file (a folder, FIFO or device): expected an HDF5 file");
    }
    const ReadingWithLibhdf5 reading;
    try {
      if (H5Fis_hdf5(path.c_str()) <= 0) {
        h5_.Fail(InputError::Kind::kMalformed, "not an HDF5 file (corrupt or truncated?)");
      }
      file_ = h5_.Check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose,
                        "cannot open the HDF5 file (corrupt or truncated?)");
      OpenEvents();
      ReadSensorResolution();
      ReadFrames();
    } catch (...) {
      CloseAll();
      throw;
    }
  }

  ~File() {
    const ReadingWithLibhdf5 reading;
    CloseAll();
  }

  const H5Context& h5() const { return h5_; }
  int64_t num_events() const { return num_events_; }
  int width() const { return width_; }
  int height() const { return height_; }
  std::vector<FrameInfo>& frames() { return frames_; }
  bool has_images_group() const { return has_images_group_; }

  // Sensor size used to validate coordinates (0 = only the uint16 range).
  void set_sensor_size(int width, int height) {
    width_ = width;
    height_ = height;
  }

  int64_t TimeAt(int64_t index) const {
    const ReadingWithLibhdf5 reading;
    int64_t t_ns = 0;
    ReadTimes(index, 1, &t_ns);
    return t_ns;
  }

  // Calls visit(index, t_ns, x, y, polarity) for the events in [first, last), validating each.
  template <typename Visitor>
  void ForEachEvent(int64_t first, int64_t last, Visitor&& visit) const {
    std::vector<int64_t> t_ns;
    std::vector<int32_t> xs;
    std::vector<int32_t> ys;
    std::vector<int32_t> ps;
    bool has_previous = false;
    int64_t previous_t_ns = 0;
    const int32_t x_limit = width_ > 0 ? width_ : 65536;
    const int32_t y_limit = height_ > 0 ? height_ : 65536;
    for (int64_t block = first; block < last; block += kEventBlock) {
      const int64_t count = std::min(kEventBlock, last - block);
      t_ns.resize(count);
      xs.resize(count);
      ys.resize(count);
      ps.resize(count);
      {
        const ReadingWithLibhdf5 reading;
        ReadTimes(block, count, t_ns.data());
        ReadSlab(h5_, xs_.get(), "events/xs", H5T_NATIVE_INT32, block, count, xs.data());
        ReadSlab(h5_, ys_.get(), "events/ys", H5T_NATIVE_INT32, block, count, ys.data());
        ReadPolarities(block, count, ps.data());
      }
      for (int64_t i = 0; i < count; ++i) {
        const int64_t index = block + i;
        if (xs[i] < 0 || xs[i] >= x_limit)
          FailEvent(InputError::Kind::kOutOfRange, "xs", index,
                    std::to_string(xs[i]) + " is outside the sensor (x must be in [0, " +
                        std::to_string(x_limit) + "))");
        if (ys[i] < 0 || ys[i] >= y_limit)
          FailEvent(InputError::Kind::kOutOfRange, "ys", index,
                    std::to_string(ys[i]) + " is outside the sensor (y must be in [0, " +
                        std::to_string(y_limit) + "))");
        if (ps[i] < -1 || ps[i] > 1)
          FailEvent(InputError::Kind::kOutOfRange, "ps", index,
                    std::to_string(ps[i]) + " is not a polarity (expected 0/1 or -1/1)");
        if (has_previous && t_ns[i] < previous_t_ns)
          FailEvent(InputError::Kind::kNotMonotonic, "ts", index, "timestamps must not decrease");
        has_previous = true;
        previous_t_ns = t_ns[i];
        visit(t_ns[i], xs[i], ys[i], ps[i] > 0 ? 1 : -1);
      }
    }
  }

  Image ReadImage(int index) const {
    const ReadingWithLibhdf5 reading;
    const std::string name = std::string(kImagesGroup) + "/" + image_datasets_[index];
    const Handle dataset = h5_.Check(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), H5Dclose,
                                     "cannot open " + name);
    const std::vector<hsize_t> dims = Dimensions(h5_, dataset.get(), name);
    if (dims.size() != 2) h5_.Fail(InputError::Kind::kMalformed, name + " must be a 2-D image");
    // Compared as hsize_t: a cast to int would wrap a corrupt extent of 2^32 + height rows onto
    // the sensor's height and let H5Dread write past the image.
    if (dims[0] != static_cast<hsize_t>(height_) || dims[1] != static_cast<hsize_t>(width_)) {
      h5_.Fail(InputError::Kind::kSizeMismatch,
               name + " is " + std::to_string(dims[1]) + "x" + std::to_string(dims[0]) +
                   ", the sensor is " + std::to_string(width_) + "x" + std::to_string(height_));
    }
    const Handle type =
        h5_.Check(H5Dget_type(dataset.get()), H5Tclose, "unreadable type of " + name);
    const H5T_class_t type_class = H5Tget_class(type.get());
    Image image(height_, width_);
    if (type_class == H5T_FLOAT) {
      h5_.CheckStatus(
          H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, image.data()),
          "cannot read " + name);
      return image;
    }
    const size_t bytes = H5Tget_size(type.get());
    if (type_class != H5T_INTEGER || H5Tget_sign(type.get()) != H5T_SGN_NONE || bytes > 2) {
      h5_.Fail(InputError::Kind::kMalformed,
               name + " must hold uint8, uint16 or floating-point pixels");
    }
    std::vector<uint16_t> pixels(image.size());
    h5_.CheckStatus(
        H5Dread(dataset.get(), H5T_NATIVE_UINT16, H5S_ALL, H5S_ALL, H5P_DEFAULT, pixels.data()),
        "cannot read " + name);
    const double max_value = bytes == 1 ? 255.0 : 65535.0;
    for (Eigen::Index i = 0; i < image.size(); ++i) image.data()[i] = pixels[i] / max_value;
    return image;
  }

 private:
  // Closes every HDF5 object, the file last.
  void CloseAll() {
    ps_enum_type_ = Handle();
    ps_ = Handle();
    ts_ = Handle();
    ys_ = Handle();
    xs_ = Handle();
    file_ = Handle();
  }

  [[noreturn]] void FailEvent(InputError::Kind kind, const char* dataset, int64_t index,
                              const std::string& what) const {
    h5_.Fail(kind, std::string("events/") + dataset + "[" + std::to_string(index) + "]: " + what);
  }

  void OpenEvents() {
    const auto open = [&](const char* name) {
      const std::string full = std::string(kEventsGroup) + "/" + name;
      if (H5Lexists(file_.get(), kEventsGroup, H5P_DEFAULT) <= 0 ||
          H5Lexists(file_.get(), full.c_str(), H5P_DEFAULT) <= 0) {
        h5_.Fail(InputError::Kind::kMalformed, "missing dataset " + full);
      }
      Handle dataset = h5_.Check(H5Dopen2(file_.get(), full.c_str(), H5P_DEFAULT), H5Dclose,
                                 "cannot open dataset " + full);
      const std::vector<hsize_t> dims = Dimensions(h5_, dataset.get(), full);
      if (dims.size() != 1) h5_.Fail(InputError::Kind::kMalformed, full + " must be 1-D");
      CheckStored(h5_, dataset.get(), full, dims);
      if (name == std::string("xs")) num_events_ = static_cast<int64_t>(dims[0]);
      if (static_cast<int64_t>(dims[0]) != num_events_) {
        h5_.Fail(InputError::Kind::kMalformed, full + " holds " + std::to_string(dims[0]) +
                                                   " values, events/xs " +
                                                   std::to_string(num_events_));
      }
      return dataset;
    };
    xs_ = open("xs");
    ys_ = open("ys");
    ts_ = open("ts");
    ps_ = open("ps");

    const Handle ts_type =
        h5_.Check(H5Dget_type(ts_.get()), H5Tclose, "unreadable type of events/ts");
    ts_is_float_ = H5Tget_class(ts_type.get()) == H5T_FLOAT;
    if (!ts_is_float_ && H5Tget_class(ts_type.get()) != H5T_INTEGER) {
      h5_.Fail(InputError::Kind::kMalformed,
               "events/ts must hold floating-point seconds or integer times");
    }
    if (!ts_is_float_ && HasAttribute(ts_.get(), kTsUnit)) {
      const std::string unit = ReadStringAttribute(h5_, ts_.get(), kTsUnit, "events/ts");
      if (unit == "ns") {
        ts_unit_ns_ = 1;
      } else if (unit == "us") {
        ts_unit_ns_ = 1000;
      } else {
        h5_.Fail(
            InputError::Kind::kMalformed,
            "events/ts attribute ts_unit is '" + MessageExcerpt(unit) + "', expected 'ns' or 'us'");
      }
    }

    const Handle ps_type =
        h5_.Check(H5Dget_type(ps_.get()), H5Tclose, "unreadable type of events/ps");
    const H5T_class_t ps_class = H5Tget_class(ps_type.get());
    if (ps_class == H5T_ENUM) {
      // h5py stores bool as an enum over int8; HDF5 does not convert enums to integers, so
      // they are read raw through a native copy of the enum type.
      if (H5Tget_size(ps_type.get()) != 1)
        h5_.Fail(InputError::Kind::kMalformed, "events/ps: only 1-byte enums (bool) are supported");
      ps_enum_type_ = h5_.Check(H5Tget_native_type(ps_type.get(), H5T_DIR_ASCEND), H5Tclose,
                                "unreadable type of events/ps");
    } else if (ps_class != H5T_INTEGER) {
      h5_.Fail(InputError::Kind::kMalformed, "events/ps must hold integers or bools");
    }
  }

  void ReadTimes(int64_t first, int64_t count, int64_t* t_ns) const {
    if (ts_is_float_) {
      std::vector<double> seconds(count);
      ReadSlab(h5_, ts_.get(), "events/ts", H5T_NATIVE_DOUBLE, first, count, seconds.data());
      for (int64_t i = 0; i < count; ++i) {
        if (!std::isfinite(seconds[i]) || std::fabs(seconds[i]) >= kMaxSeconds) {
          FailEvent(InputError::Kind::kOutOfRange, "ts", first + i, "not a finite time in seconds");
        }
        t_ns[i] = SecondsToNanoseconds(seconds[i]);
      }
      return;
    }
    ReadSlab(h5_, ts_.get(), "events/ts", H5T_NATIVE_INT64, first, count, t_ns);
    if (ts_unit_ns_ == 1) return;
    const int64_t limit = INT64_MAX / ts_unit_ns_;
    for (int64_t i = 0; i < count; ++i) {
      if (t_ns[i] > limit || t_ns[i] < -limit)
        FailEvent(InputError::Kind::kOutOfRange, "ts", first + i,
                  "too large for int64 nanoseconds");
      t_ns[i] *= ts_unit_ns_;
    }
  }

  void ReadPolarities(int64_t first, int64_t count, int32_t* polarity) const {
    if (ps_enum_type_.get() < 0) {
      ReadSlab(h5_, ps_.get(), "events/ps", H5T_NATIVE_INT32, first, count, polarity);
      return;
    }
    std::vector<int8_t> raw(count);
    ReadSlab(h5_, ps_.get(), "events/ps", ps_enum_type_.get(), first, count, raw.data());
    std::copy(raw.begin(), raw.end(), polarity);
  }

  void ReadSensorResolution() {
    if (!HasAttribute(file_.get(), kSensorResolution)) return;
    const std::string what = std::string("root attribute '") + kSensorResolution + "'";
    const Handle attribute = h5_.Check(H5Aopen(file_.get(), kSensorResolution, H5P_DEFAULT),
                                       H5Aclose, "unreadable " + what);
    const Handle space = h5_.Check(H5Aget_space(attribute.get()), H5Sclose, "unreadable " + what);
    int64_t resolution[2] = {0, 0};
    if (H5Sget_simple_extent_npoints(space.get()) != 2)
      h5_.Fail(InputError::Kind::kMalformed, what + " must hold [height, width]");
    h5_.CheckStatus(H5Aread(attribute.get(), H5T_NATIVE_INT64, resolution), "unreadable " + what);
    if (resolution[0] <= 0 || resolution[1] <= 0) {
      h5_.Fail(InputError::Kind::kOutOfRange, what + " must hold a positive [height, width]");
    }
    if (resolution[0] > static_cast<int64_t>(kMaxImageSide) ||
        resolution[1] > static_cast<int64_t>(kMaxImageSide)) {
      h5_.Fail(InputError::Kind::kOutOfRange,
               what + " declares a " + std::to_string(resolution[1]) + "x" +
                   std::to_string(resolution[0]) + " sensor: beyond the " +
                   std::to_string(kMaxImageSide) + " pixels a side and " +
                   std::to_string(kMaxSensorPixels) + " pixels (8192x8192) evfs reads");
    }
    CheckSensorPixels(what + " declares a", resolution[1], resolution[0]);
    height_ = static_cast<int>(resolution[0]);
    width_ = static_cast<int>(resolution[1]);
  }

  // Fails when a width x height sensor (each side already at most 65536) is beyond
  // kMaxSensorPixels; `what` names where the size comes from.
  void CheckSensorPixels(const std::string& what, int64_t width, int64_t height) const {
    if (width * height > kMaxSensorPixels) {
      h5_.Fail(InputError::Kind::kOutOfRange,
               what + " " + std::to_string(width) + "x" + std::to_string(height) +
                   " sensor: more than the " + std::to_string(kMaxSensorPixels) +
                   " pixels (8192x8192) evfs reads");
    }
  }

  void ReadFrames() {
    has_images_group_ = H5Lexists(file_.get(), kImagesGroup, H5P_DEFAULT) > 0;
    if (!has_images_group_) return;
    const Handle group = h5_.Check(H5Gopen2(file_.get(), kImagesGroup, H5P_DEFAULT), H5Gclose,
                                   "cannot open group images");
    H5G_info_t info;
    h5_.CheckStatus(H5Gget_info(group.get(), &info), "cannot list group images");
    std::vector<std::pair<FrameInfo, std::string>> frames;
    for (hsize_t i = 0; i < info.nlinks; ++i) {
      const ssize_t length = H5Lget_name_by_idx(group.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i,
                                                nullptr, 0, H5P_DEFAULT);
      if (length < 0) h5_.Fail(InputError::Kind::kMalformed, "cannot list group images");
      std::string name(static_cast<size_t>(length) + 1, '\0');
      H5Lget_name_by_idx(group.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, &name[0], name.size(),
                         H5P_DEFAULT);
      name.resize(static_cast<size_t>(length));
      if (HasControlCharacter(name) || name.size() > kMaxImageNameBytes) {
        h5_.Fail(InputError::Kind::kMalformed,
                 "images/" + MessageExcerpt(name) +
                     ": expected a printable dataset name of at most " +
                     std::to_string(kMaxImageNameBytes) + " bytes");
      }
      const std::string full = std::string(kImagesGroup) + "/" + name;
      const Handle dataset = h5_.Check(H5Dopen2(group.get(), name.c_str(), H5P_DEFAULT), H5Dclose,
                                       full + " is not a dataset");
      const std::vector<hsize_t> dims = Dimensions(h5_, dataset.get(), full);
      if (dims.size() != 2) h5_.Fail(InputError::Kind::kMalformed, full + " must be a 2-D image");
      CheckStored(h5_, dataset.get(), full, dims);
      if (width_ == 0 || height_ == 0) {
        if (dims[0] < 1 || dims[1] < 1 || dims[0] > kMaxImageSide || dims[1] > kMaxImageSide) {
          h5_.Fail(InputError::Kind::kMalformed,
                   full + " is " + std::to_string(dims[1]) + "x" + std::to_string(dims[0]) +
                       ": each side must be 1 to " + std::to_string(kMaxImageSide) + " pixels");
        }
        CheckSensorPixels(full + " is a frame of a", static_cast<int64_t>(dims[1]),
                          static_cast<int64_t>(dims[0]));
        height_ = static_cast<int>(dims[0]);
        width_ = static_cast<int>(dims[1]);
      }
      // Every frame has the sensor's size, checked before anything is allocated for either: a
      // sensor_resolution of 65535x65535 over 240x180 frames made `info` allocate for 4 G
      // pixels. Compared as hsize_t, like ReadImage does.
      if (dims[0] != static_cast<hsize_t>(height_) || dims[1] != static_cast<hsize_t>(width_)) {
        h5_.Fail(InputError::Kind::kSizeMismatch,
                 full + " is " + std::to_string(dims[1]) + "x" + std::to_string(dims[0]) +
                     ", the sensor is " + std::to_string(width_) + "x" + std::to_string(height_));
      }
      FrameInfo frame;
      frame.t_ns = SecondsToNanoseconds(ReadDoubleAttribute(h5_, dataset.get(), kTimestamp, full));
      frame.path = HasAttribute(dataset.get(), kPath)
                       ? ReadStringAttribute(h5_, dataset.get(), kPath, full)
                       : full;
      const std::string path_problem = ImagePathProblem(frame.path);
      if (!path_problem.empty()) h5_.Fail(InputError::Kind::kMalformed, full + ": " + path_problem);
      frame.has_exposure =
          HasAttribute(dataset.get(), kExposureStart) || HasAttribute(dataset.get(), kExposureEnd);
      if (frame.has_exposure) {
        frame.exposure_begin_ns =
            SecondsToNanoseconds(ReadDoubleAttribute(h5_, dataset.get(), kExposureStart, full));
        frame.exposure_end_ns =
            SecondsToNanoseconds(ReadDoubleAttribute(h5_, dataset.get(), kExposureEnd, full));
        if (frame.exposure_end_ns <= frame.exposure_begin_ns)
          h5_.Fail(InputError::Kind::kOutOfRange, full + ": exposure must end after it starts");
      }
      frames.emplace_back(std::move(frame), name);
    }
    // Dataset names need not sort like their times (image9 after image10), so order by time.
    std::stable_sort(frames.begin(), frames.end(),
                     [](const auto& a, const auto& b) { return a.first.t_ns < b.first.t_ns; });
    for (size_t i = 0; i < frames.size(); ++i) {
      if (i > 0 && frames[i].first.t_ns == frames[i - 1].first.t_ns) {
        h5_.Fail(InputError::Kind::kNotMonotonic, "images/" + frames[i].second +
                                                      " has the same timestamp as images/" +
                                                      frames[i - 1].second);
      }
      frames_.push_back(frames[i].first);
      image_datasets_.push_back(frames[i].second);
    }
  }

  H5Context h5_;
  Handle file_;
  Handle xs_;
  Handle ys_;
  Handle ts_;
  Handle ps_;
  Handle ps_enum_type_;  // set when events/ps is an enum (bool)
  int64_t num_events_ = 0;
  bool ts_is_float_ = true;
  int64_t ts_unit_ns_ = 1000;  // integer timestamps without ts_unit are microseconds
  int width_ = 0;
  int height_ = 0;
  std::vector<FrameInfo> frames_;
  std::vector<std::string> image_datasets_;  // names inside /images, in frames_ order
  bool has_images_group_ = false;
};

Hdf5DataSource::Hdf5DataSource(const std::string& path)
    : Hdf5DataSource(std::make_unique<File>(path)) {}

Hdf5DataSource::Hdf5DataSource(std::unique_ptr<File> file)
    : DataSource(file->h5().path(), file->width(), file->height(), std::move(file->frames())),
      file_(std::move(file)) {
  if (frames_.empty()) {
    no_frames_reason_ =
        file_->has_images_group() ? "its group /images holds no image" : "it has no group /images";
  }
  if (width_ == 0 || height_ == 0) {
    // Neither sensor_resolution nor frames: the events say how large the sensor is at least.
    const EventSummary summary = Summarize();
    width_ = summary.max_x + 1;
    height_ = summary.max_y + 1;
    file_->set_sensor_size(width_, height_);
  }
}

Hdf5DataSource::~Hdf5DataSource() = default;

int64_t Hdf5DataSource::num_events() const { return file_->num_events(); }

Image Hdf5DataSource::ReadImage(int index) const {
  CheckFrameIndex(index);
  return file_->ReadImage(index);
}

int64_t Hdf5DataSource::LowerBound(int64_t t_ns) const {
  int64_t low = 0;
  int64_t high = file_->num_events();
  while (low < high) {
    const int64_t middle = low + (high - low) / 2;
    if (file_->TimeAt(middle) < t_ns) {
      low = middle + 1;
    } else {
      high = middle;
    }
  }
  return low;
}

EventStream Hdf5DataSource::ReadEventRange(int64_t first, int64_t last) const {
  EventStream events(width_, height_);
  if (last <= first) return events;
  events.reserve(static_cast<size_t>(last - first));
  file_->ForEachEvent(first, last, [&](int64_t t_ns, int32_t x, int32_t y, int polarity) {
    events.push_back(t_ns, static_cast<uint16_t>(x), static_cast<uint16_t>(y),
                     static_cast<int8_t>(polarity));
  });
  return events;
}

EventStream Hdf5DataSource::ReadEvents(int64_t t_begin_ns, int64_t t_end_ns) const {
  if (t_end_ns <= t_begin_ns) return EventStream(width_, height_);
  return ReadEventRange(LowerBound(t_begin_ns), LowerBound(t_end_ns));
}

EventStream Hdf5DataSource::ReadAllEvents() const { return ReadEventRange(0, file_->num_events()); }

EventSummary Hdf5DataSource::Summarize() const {
  EventSummary summary;
  file_->ForEachEvent(
      0, file_->num_events(),
      [&](int64_t t_ns, int32_t x, int32_t y, int polarity) { summary.Add(t_ns, x, y, polarity); });
  return summary;
}

// ---------------------------------------------------------------------------------------------
// Writing.

namespace {

class Hdf5Writer {
 public:
  explicit Hdf5Writer(const std::string& path) : h5_(path, InputError::Kind::kUnwritable) {
    file_ = h5_.Check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
                      "cannot create the HDF5 file");
  }

  Handle CreateGroup(const char* name) {
    return h5_.Check(H5Gcreate2(file_.get(), name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                     std::string("cannot create group ") + name);
  }

  // Creates dataset `name` under `parent` with `dims` of `file_type` and writes `data` (given
  // as `memory_type`) into it.
  Handle WriteDataset(hid_t parent, const std::string& name, const std::vector<hsize_t>& dims,
                      hid_t file_type, hid_t memory_type, const void* data) {
    const std::string what = "cannot write dataset " + name;
    const Handle space = h5_.Check(
        H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, what);
    Handle dataset = h5_.Check(H5Dcreate2(parent, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                                          H5P_DEFAULT, H5P_DEFAULT),
                               H5Dclose, what);
    hsize_t count = 1;
    for (const hsize_t dim : dims) count *= dim;
    if (count > 0)
      h5_.CheckStatus(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
                      what);
    return dataset;
  }

  void WriteAttribute(hid_t object, const char* name, hid_t file_type, hid_t memory_type,
                      hsize_t count, const void* data) {
    const std::string what = std::string("cannot write attribute ") + name;
    const Handle space = count == 1
                             ? h5_.Check(H5Screate(H5S_SCALAR), H5Sclose, what)
                             : h5_.Check(H5Screate_simple(1, &count, nullptr), H5Sclose, what);
    const Handle attribute = h5_.Check(
        H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
    h5_.CheckStatus(H5Awrite(attribute.get(), memory_type, data), what);
  }

  void WriteSecondsAttribute(hid_t object, const char* name, int64_t t_ns) {
    const double seconds = NanosecondsToSeconds(t_ns);
    WriteAttribute(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 1, &seconds);
  }

  void WriteStringAttribute(hid_t object, const char* name, const std::string& value) {
    const std::string what = std::string("cannot write attribute ") + name;
    const Handle type = h5_.Check(H5Tcopy(H5T_C_S1), H5Tclose, what);
    // Fixed length, NUL-padded: what h5py writes for fixed strings; an empty one still needs a
    // byte.
    h5_.CheckStatus(H5Tset_size(type.get(), std::max<size_t>(1, value.size())), what);
    h5_.CheckStatus(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), what);
    const std::string padded = value.empty() ? std::string(1, '\0') : value;
    WriteAttribute(object, name, type.get(), type.get(), 1, padded.data());
  }

  hid_t file() const { return file_.get(); }

  void Close() {
    h5_.CheckStatus(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), "cannot write the HDF5 file");
    file_ = Handle();
  }

 private:
  H5Context h5_;
  Handle file_;
};

// True when every timestamp survives the trip through float64 seconds exactly.
bool FloatSecondsAreExact(const std::vector<int64_t>& t_ns) {
  return std::all_of(t_ns.begin(), t_ns.end(),
                     [](int64_t t) { return SecondsToNanoseconds(NanosecondsToSeconds(t)) == t; });
}

}  // namespace

void WriteHdf5(const std::string& path, const EventStream& events,
               const std::vector<FrameInfo>& frames, const std::vector<Image>& images) {
  if (frames.size() != images.size()) {
    throw InvalidArgumentError("WriteHdf5: " + std::to_string(frames.size()) + " frames but " +
                               std::to_string(images.size()) + " images");
  }
  // A crash here is not the user's file's doing: errors are silenced, the region not marked.
  const ScopedHdf5ErrorsSilenced silenced;
  Hdf5Writer writer(path);

  int height = events.height();
  int width = events.width();
  if ((width <= 0 || height <= 0) && !images.empty()) {
    height = static_cast<int>(images.front().rows());
    width = static_cast<int>(images.front().cols());
  }
  if (width > 0 && height > 0) {
    const int32_t resolution[2] = {height, width};
    writer.WriteAttribute(writer.file(), kSensorResolution, H5T_STD_I32LE, H5T_NATIVE_INT32, 2,
                          resolution);
  }

  writer.WriteStringAttribute(writer.file(), kWrittenBy, kEvfs);

  const Handle events_group = writer.CreateGroup(kEventsGroup);
  const std::vector<hsize_t> event_dims = {static_cast<hsize_t>(events.size())};
  writer.WriteDataset(events_group.get(), "xs", event_dims, H5T_STD_U16LE, H5T_NATIVE_UINT16,
                      events.x().data());
  writer.WriteDataset(events_group.get(), "ys", event_dims, H5T_STD_U16LE, H5T_NATIVE_UINT16,
                      events.y().data());
  if (FloatSecondsAreExact(events.t_ns())) {
    std::vector<double> seconds(events.size());
    std::transform(events.t_ns().begin(), events.t_ns().end(), seconds.begin(),
                   NanosecondsToSeconds);
    writer.WriteDataset(events_group.get(), "ts", event_dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                        seconds.data());
  } else {
    const Handle ts = writer.WriteDataset(events_group.get(), "ts", event_dims, H5T_STD_I64LE,
                                          H5T_NATIVE_INT64, events.t_ns().data());
    writer.WriteStringAttribute(ts.get(), kTsUnit, "ns");
  }
  std::vector<int8_t> polarity(events.size());
  std::transform(events.polarity().begin(), events.polarity().end(), polarity.begin(),
                 [](int8_t p) { return static_cast<int8_t>(p > 0 ? 1 : 0); });
  writer.WriteDataset(events_group.get(), "ps", event_dims, H5T_STD_I8LE, H5T_NATIVE_INT8,
                      polarity.data());

  if (!frames.empty()) {
    const Handle images_group = writer.CreateGroup(kImagesGroup);
    for (size_t i = 0; i < frames.size(); ++i) {
      const Image& image = images[i];
      char name[32];
      std::snprintf(name, sizeof(name), "image%09zu", i);
      const std::vector<hsize_t> dims = {static_cast<hsize_t>(image.rows()),
                                         static_cast<hsize_t>(image.cols())};
      Handle dataset;
      if (MinimalBitDepth(image) == 8) {
        std::vector<uint8_t> pixels(image.size());
        for (Eigen::Index k = 0; k < image.size(); ++k)
          pixels[k] = static_cast<uint8_t>(std::lround(image.data()[k] * 255.0));
        dataset = writer.WriteDataset(images_group.get(), name, dims, H5T_STD_U8LE,
                                      H5T_NATIVE_UINT8, pixels.data());
      } else {
        std::vector<uint16_t> pixels(image.size());
        for (Eigen::Index k = 0; k < image.size(); ++k)
          pixels[k] = static_cast<uint16_t>(
              std::lround(std::min(1.0, std::max(0.0, image.data()[k])) * 65535.0));
        dataset = writer.WriteDataset(images_group.get(), name, dims, H5T_STD_U16LE,
                                      H5T_NATIVE_UINT16, pixels.data());
      }
      writer.WriteSecondsAttribute(dataset.get(), kTimestamp, frames[i].t_ns);
      if (frames[i].has_exposure) {
        writer.WriteSecondsAttribute(dataset.get(), kExposureStart, frames[i].exposure_begin_ns);
        writer.WriteSecondsAttribute(dataset.get(), kExposureEnd, frames[i].exposure_end_ns);
      }
      writer.WriteStringAttribute(dataset.get(), kPath, frames[i].path);
    }
  }
  writer.Close();
}

bool IsHdf5WrittenByEvfs(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  try {
    const H5Context h5(path, InputError::Kind::kMalformed);
    const ReadingWithLibhdf5 reading;
    if (H5Fis_hdf5(path.c_str()) <= 0) return false;
    const Handle file =
        h5.Check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "cannot open");
    return HasAttribute(file.get(), kWrittenBy) &&
           ReadStringAttribute(h5, file.get(), kWrittenBy, "the file's") == kEvfs;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace evfs
