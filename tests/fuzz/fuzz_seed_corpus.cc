// Writes the seed corpora of the fuzz targets from the shared DAVIS snippets, into the build
// folder (never into the repository):
//   OUT/event_text/  the first 4 KB of every events.txt (cut at a line end), and 20 KB of one
//                    so that windowed reads take the binary search
//   OUT/frame_list/  every images.txt and exposures.txt, and each images.txt joined by a NUL
//                    byte to the exposures.txt beside it (see frame_list_fuzzer.cc)
//   OUT/aedat4/      the same tiny recordings written by WriteAedat4 with each compression
//                    (several packets each, a data table), and the header and first packets
//                    of the real recordings with their table position set to -1 (no table):
//                    DV's, and one cut by another tool (its IOHeader aligned differently)
//   OUT/aedat_legacy/ the first events of every snippet of at most 240x180 pixels as jAER AEDAT
//                    2.0 (DAVIS240 addresses) and as cAER AEDAT 3.1 (two polarity packets);
//                    no frames, as a whole-sensor frame alone is 86 KB (3.1) or 1.4 MB (2.0)
//   OUT/hdf5_io/     tiny recordings cut from the snippets and converted to HDF5 by
//                    ConvertRecording, the code behind `evfs convert`
//   OUT/rosbag/      the same tiny recordings as ROS bags with each compression, 8 events per
//                    message, written by tests/io/write_rosbag.py (none when python3-rosbag is
//                    not installed)
//
//   fuzz_seed_corpus DATA_DIR OUT
#include <flatbuffers/flatbuffers.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/io/aedat4.h"
#include "evfs/io/data_source.h"
#include "evfs/io/event_text.h"
#include "evfs/io/frame_list.h"
#include "evfs/io/image_io.h"
#include "evfs/io/text_folder.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

constexpr size_t kEventSeedBytes = 4 * 1024;
// Every images.txt and exposures.txt of the shared data is smaller.
constexpr size_t kListSeedBytes = 64 * 1024;
// More than the 16 KB below which the event reader scans linearly instead of searching.
constexpr size_t kLargeEventSeedBytes = 20 * 1024;
// Tiny recordings keep HDF5 seeds at a few KB: the first events inside a corner of the sensor.
constexpr int kCropWidth = 16;
constexpr int kCropHeight = 12;
constexpr size_t kCropEvents = 40;
// Beyond ~50 days float64 seconds lose nanoseconds, so WriteHdf5 stores int64 ns with ts_unit.
constexpr int64_t kFarFutureNs = 100LL * 24 * 3600 * 1000000000LL;

std::string ReadPrefix(const fs::path& path, size_t bytes) {
  std::ifstream stream(path, std::ios::binary);
  std::string text(bytes, '\0');
  stream.read(&text[0], static_cast<std::streamsize>(bytes));
  text.resize(static_cast<size_t>(stream.gcount()));
  return text.substr(0, text.rfind('\n') + 1);  // whole lines only
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream stream(path, std::ios::binary);
  stream << text;
  if (!stream) throw InputError(InputError::Kind::kUnwritable, path.string(), 0, "cannot write");
}

// The first kCropEvents events inside the crop (time-shifted by `shift_ns`), and the first two
// frames cropped to it when `with_frames`.
void WriteTinyRecording(const DataSource& source, bool with_frames, int64_t shift_ns,
                        const fs::path& h5_path, const fs::path& scratch) {
  EventStream events(kCropWidth, kCropHeight);
  const EventStream all = source.ReadAllEvents();
  for (size_t i = 0; i < all.size() && events.size() < kCropEvents; ++i) {
    if (all.x(i) < kCropWidth && all.y(i) < kCropHeight) {
      events.push_back(all.t_ns(i) + shift_ns, all.x(i), all.y(i), all.polarity(i));
    }
  }
  std::vector<FrameInfo> frames;
  std::vector<Image> images;
  for (int i = 0; with_frames && i < std::min<int>(2, source.frames().size()); ++i) {
    FrameInfo frame = source.frames()[i];
    frame.t_ns += shift_ns;
    frame.exposure_begin_ns += shift_ns;
    frame.exposure_end_ns += shift_ns;
    frames.push_back(frame);
    images.push_back(source.ReadImage(i).topLeftCorner(kCropHeight, kCropWidth));
  }
  fs::remove_all(scratch);
  WriteDataFolder(scratch.string(), events, frames, images);
  ConvertRecording(scratch.string(), h5_path.string());
  fs::remove_all(scratch);
}

// A tiny recording (an HDF5 seed) as AEDAT 4 with each compression, in packets of a few
// events so that windowed reads seek.
constexpr int kSeedEventsPerPacket = 8;

void WriteAedat4Seeds(const fs::path& h5_path, const fs::path& out_stem) {
  const auto source = DataSource::Open(h5_path.string());
  if (source->width() <= 0) return;  // no events nor frames, so no sensor size: nothing to write
  std::vector<Image> images;
  for (int i = 0; i < static_cast<int>(source->frames().size()); ++i) {
    images.push_back(source->ReadImage(i));
  }
  for (const Aedat4Compression compression :
       {Aedat4Compression::kNone, Aedat4Compression::kLz4, Aedat4Compression::kZstd}) {
    Aedat4WriteOptions options;
    options.compression = compression;
    options.max_events_per_packet = kSeedEventsPerPacket;
    WriteAedat4(out_stem.string() + "_" + Aedat4CompressionName(compression) + ".aedat4",
                source->ReadAllEvents(), source->frames(), images, options);
  }
}

// The version line, IOHeader and first kRealSeedPackets packets of a real recording, its
// data_table_position (slot 1 of the IOHeader table) set to -1: a recording without a table.
constexpr int kRealSeedPackets = 2;

void WriteRealSeed(const fs::path& aedat4_path, const fs::path& seed_path) {
  std::ifstream stream(aedat4_path, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(stream)),
                         std::istreambuf_iterator<char>());
  constexpr size_t kVersionLineBytes = 14;
  if (file.size() < kVersionLineBytes + 4) return;
  uint32_t header_bytes = 0;
  std::memcpy(&header_bytes, file.data() + kVersionLineBytes, 4);
  size_t end = kVersionLineBytes + 4 + header_bytes;
  if (end > file.size()) return;
  const std::vector<uint8_t> header(file.begin() + kVersionLineBytes, file.begin() + end);
  const uint8_t* field =
      flatbuffers::GetSizePrefixedRoot<flatbuffers::Table>(header.data())->GetAddressOf(6);
  if (field == nullptr) return;
  std::string seed = file;
  const int64_t no_table = -1;
  std::memcpy(&seed[kVersionLineBytes + static_cast<size_t>(field - header.data())], &no_table, 8);
  for (int packet = 0; packet < kRealSeedPackets && end + 8 <= file.size(); ++packet) {
    int32_t size = 0;
    std::memcpy(&size, file.data() + end + 4, 4);
    end += 8 + static_cast<size_t>(size);
  }
  WriteText(seed_path, seed.substr(0, std::min(end, file.size())));
}

// The first kLegacySeedEvents events of `source` as AEDAT 2.0 and 3.1 (io/aedat_legacy/format.h),
// when they fit a DAVIS240.
constexpr size_t kLegacySeedEvents = 256;

void WriteAedatLegacySeeds(const DataSource& source, const fs::path& out_stem) {
  if (source.width() > 240 || source.height() > 180) return;
  const EventStream events =
      source.ReadEvents(std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max());
  const size_t count = std::min(events.size(), kLegacySeedEvents);
  const auto append = [](std::string* bytes, uint32_t value, bool big_endian) {
    for (int i = 0; i < 4; ++i) {
      bytes->push_back(static_cast<char>(value >> (big_endian ? 24 - 8 * i : 8 * i)));
    }
  };
  std::string v2 = "#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS240C\r\n";
  std::string v3 = "#!AER-DAT3.1\r\n#Source 1: DAVIS240C\r\n#!END-HEADER\r\n";
  for (size_t i = 0; i < count; ++i) {
    const uint32_t t_us = static_cast<uint32_t>(events.t_ns(i) / 1000);
    const uint32_t positive = events.polarity(i) > 0 ? 1 : 0;
    append(&v2,
           (static_cast<uint32_t>(179 - events.y(i)) << 22) |
               (static_cast<uint32_t>(239 - events.x(i)) << 12) | (positive << 11),
           true);
    append(&v2, t_us, true);
    if (i % (kLegacySeedEvents / 2) == 0) {
      const uint32_t number = static_cast<uint32_t>(std::min(count - i, kLegacySeedEvents / 2));
      v3 += std::string("\x01\x00\x01\x00", 4);
      for (const uint32_t field : {8u, 4u, 0u, number, number, number}) append(&v3, field, false);
    }
    append(&v3,
           (static_cast<uint32_t>(events.x(i)) << 17) | (static_cast<uint32_t>(events.y(i)) << 2) |
               (positive << 1) | 1u,
           false);
    append(&v3, t_us, false);
  }
  WriteText(out_stem.string() + ".aedat2", v2);
  WriteText(out_stem.string() + ".aedat3", v3);
}

// A tiny recording (an HDF5 seed) as ROS bags, through a data folder and the independent
// writer; nothing when python3-rosbag is missing.
void WriteRosbagSeeds(const fs::path& h5_path, const fs::path& out_stem, const fs::path& scratch) {
  if (std::system("/usr/bin/python3 -c 'import rosbag' >/dev/null 2>&1") != 0) return;
  fs::remove_all(scratch);
  ConvertRecording(h5_path.string(), scratch.string());
  for (const char* compression : {"none", "bz2", "lz4"}) {
    const std::string command = "/usr/bin/python3 " EVFS_SOURCE_DIR "/tests/io/write_rosbag.py " +
                                scratch.string() + " " + out_stem.string() + "_" + compression +
                                ".bag --events_per_message 8 --compression " + compression;
    if (std::system(command.c_str()) != 0) {
      throw InputError(InputError::Kind::kUnwritable, out_stem.string(), 0, "cannot write");
    }
  }
  fs::remove_all(scratch);
}

int Run(const fs::path& data_dir, const fs::path& out) {
  for (const char* target :
       {"event_text", "frame_list", "hdf5_io", "aedat4", "aedat_legacy", "rosbag"}) {
    fs::create_directories(out / target);
  }
  std::vector<fs::path> snippets;
  for (const fs::directory_entry& entry : fs::directory_iterator(data_dir)) {
    if (entry.is_directory()) snippets.push_back(entry.path());
  }
  std::sort(snippets.begin(), snippets.end());
  bool wrote_large = false;
  for (const fs::path& snippet : snippets) {
    const std::string name = snippet.filename().string();
    for (const char* list : {"images.txt", "exposures.txt"}) {
      if (fs::is_regular_file(snippet / list)) {
        WriteText(out / "frame_list" / (name + "_" + list),
                  ReadPrefix(snippet / list, kListSeedBytes));
      }
    }
    if (fs::is_regular_file(snippet / "exposures.txt")) {
      WriteText(out / "frame_list" / (name + "_both"),
                ReadPrefix(snippet / "images.txt", kListSeedBytes) + '\0' +
                    ReadPrefix(snippet / "exposures.txt", kListSeedBytes));
    }
    if (!fs::is_regular_file(snippet / "events.txt")) continue;
    WriteText(out / "event_text" / name, ReadPrefix(snippet / "events.txt", kEventSeedBytes));
    if (!wrote_large) {
      WriteText(out / "event_text" / (name + "_large"),
                ReadPrefix(snippet / "events.txt", kLargeEventSeedBytes));
      wrote_large = true;
    }
    const auto source = DataSource::Open(snippet.string());
    const fs::path scratch = out / "tiny_recording";
    WriteTinyRecording(*source, true, 0, out / "hdf5_io" / (name + ".h5"), scratch);
    WriteTinyRecording(*source, false, 0, out / "hdf5_io" / (name + "_events.h5"), scratch);
    WriteTinyRecording(*source, false, kFarFutureNs, out / "hdf5_io" / (name + "_ns.h5"), scratch);
    WriteAedat4Seeds(out / "hdf5_io" / (name + ".h5"), out / "aedat4" / name);
    WriteAedat4Seeds(out / "hdf5_io" / (name + "_ns.h5"), out / "aedat4" / (name + "_ns"));
    WriteAedatLegacySeeds(*source, out / "aedat_legacy" / name);
    WriteRosbagSeeds(out / "hdf5_io" / (name + ".h5"), out / "rosbag" / name, scratch);
  }
  for (const char* folder : {"aedat4_dvxplorer_sample", "aedat4_davis346_street"}) {
    const fs::path recording = data_dir / folder / "sample.aedat4";
    if (fs::is_regular_file(recording)) WriteRealSeed(recording, out / "aedat4" / folder);
  }
  std::printf("seed corpora from %zu snippets of %s in %s\n", snippets.size(), data_dir.c_str(),
              out.c_str());
  return 0;
}

}  // namespace
}  // namespace evfs

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: fuzz_seed_corpus DATA_DIR OUT\n");
    return 2;
  }
  try {
    return evfs::Run(argv[1], argv[2]);
  } catch (const evfs::Error& error) {
    std::fprintf(stderr, "fuzz_seed_corpus: %s\n", error.what());
    return 2;
  }
}
