# evfs — one-command entry points (see README.md).
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps build run test test-sanitize bench clean fuzz train-denoiser install python

all: build

deps:
	@bash scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) > /dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The main job: a synthetic scene through the whole pipeline, results in out/demo.
run: build
	./$(BUILD_DIR)/examples/evfs demo --out=out/demo --overwrite

# The Python module evfs (python/, pybind11) into $(BUILD_DIR)/python, for Debian's python3.
python: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DEVFS_BUILD_PYTHON=ON $(CMAKE_FLAGS) > /dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target evfs_python
	@echo "built $$(ls $(BUILD_DIR)/python/evfs*.so); use it with:"
	@echo "  PYTHONPATH=$(BUILD_DIR)/python /usr/bin/python3 -c 'import evfs; help(evfs)'"

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# The whole suite under AddressSanitizer and UndefinedBehaviorSanitizer, in its own build folder.
test-sanitize: deps
	@$(MAKE) --no-print-directory test BUILD_DIR=build-asan \
	  CMAKE_FLAGS="-DEVFS_SANITIZE=ON -DEVFS_WERROR=ON -DEVFS_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo"

# libFuzzer targets (clang, ASan+UBSan) in build-fuzz/, each run for FUZZ_SECONDS from seeds
# cut from the shared data; stops at the first finding, whose input is left in
# build-fuzz/tests/fuzz/findings/. libhdf5 itself hangs or runs out of memory on some corrupt
# files (README.md, Robustness), so the HDF5 target runs in fork mode, which records those in
# findings/ and goes on; a crash still stops it. rosbag_format_fuzzer (evfs' own bag checks and
# message decoders, in memory) starts from rosbag_fuzzer's seeds.
FUZZ_SECONDS ?= 60
FUZZ_TARGETS = event_text_fuzzer frame_list_fuzzer hdf5_io_fuzzer aedat4_fuzzer aedat_legacy_fuzzer \
  rosbag_fuzzer rosbag_format_fuzzer
FUZZ_DIR = build-fuzz/tests/fuzz

fuzz:
	@bash scripts/install-deps.sh --fuzz
	@cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
	  -DCMAKE_CXX_COMPILER=clang++ -DEVFS_FUZZ=ON -DEVFS_BUILD_BENCHMARKS=OFF > /dev/null
	@cmake --build build-fuzz -j $(JOBS) --target $(FUZZ_TARGETS) fuzz_seeds
	@for target in $(FUZZ_TARGETS); do \
	  name=$${target%_fuzzer}; \
	  mkdir -p $(FUZZ_DIR)/corpus/$$name $(FUZZ_DIR)/findings; \
	  mode=; if [ $$name = hdf5_io ]; then mode=-fork=1; fi; \
	  seeds=$$name; if [ $$name = rosbag_format ]; then seeds=rosbag; fi; \
	  echo "fuzz: $$target for $(FUZZ_SECONDS) s"; \
	  $(FUZZ_DIR)/$$target $$mode -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 \
	    -print_final_stats=1 -artifact_prefix=$(FUZZ_DIR)/findings/$$name- \
	    $(FUZZ_DIR)/corpus/$$name $(FUZZ_DIR)/seeds/$$seeds || exit 1; \
	done

# Trains the residual denoiser from scratch (about an hour on 2 cores): pairs made by evfs's own
# simulator and DMR, then tools/train_denoiser/train.py; writes models/evfs_denoiser.onnx,
# models/training_log.md and the C++ equality test's reference in tests/denoiser/data.
train-denoiser:
	@bash scripts/install-deps.sh
	@bash scripts/install-deps.sh --train
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) > /dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target make_denoiser_pairs
	bash tools/train_denoiser/train.sh $(BUILD_DIR)

# The CMake package, the evfs program and the headers into PREFIX (README.md, "Use from CMake").
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD_DIR) --prefix $(PREFIX)

bench: build
	bash benchmarks/run_all.sh $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR) build-asan out
