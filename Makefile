# evfs — one-command entry points (see README.md).
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps build run test test-sanitize bench clean

all: build

deps:
	@bash scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) > /dev/null
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The main job: a synthetic scene through the whole pipeline, results in out/demo.
run: build
	./$(BUILD_DIR)/examples/evfs demo --out=out/demo

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# The whole suite under AddressSanitizer and UndefinedBehaviorSanitizer, in its own build folder.
test-sanitize: deps
	@$(MAKE) --no-print-directory test BUILD_DIR=build-asan \
	  CMAKE_FLAGS="-DEVFS_SANITIZE=ON -DEVFS_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo"

bench: build
	bash benchmarks/run_all.sh $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR) build-asan out
