# vrflow: the entry points. `make demo` and `make test` are all a new user needs; `make check` is CI's.
SHELL := /bin/bash
BUILD ?= build
JOBS ?= $(shell nproc)
BUILD_TYPE ?= Release
# ccache keys on paths relative to the checkout, so every clone (CI's included) shares one cache;
# the sanitizer builds (-g) too, whose debug information then names relative paths.
export CCACHE_BASEDIR := $(CURDIR)
export CCACHE_NOHASHDIR := 1

# Every Debian package the project needs to build, test and benchmark.
PACKAGES := build-essential cmake ninja-build ccache pkg-config clang libclang-rt-14-dev \
  libopencv-core-dev libopencv-imgproc-dev libopencv-calib3d-dev libopencv-video-dev libopencv-imgcodecs-dev libopencv-videoio-dev \
  libgtest-dev libpugixml-dev libcli11-dev \
  nlohmann-json3-dev libxxhash-dev libzstd-dev libzmq3-dev libopenmpi-dev openmpi-bin libxml2-utils procps \
  libbullet-dev libeigen3-dev libevdev-dev libosmesa6-dev libglfw3-dev xvfb xdotool libpng-dev qt6-base-dev libgraphviz-dev \
  libsodium-dev openssh-server openssh-client clang-format dpkg-dev libspdlog-dev \
  munge slurmctld slurmd slurm-client python3-jsonschema bsdutils libopenvdb-dev libboost-dev libtbb-dev \
  pybind11-dev python3-dev python3-numpy python3-pytest

.PHONY: deps build test check format demo clean install

deps:
	@missing=$$(for p in $(PACKAGES); do \
	  dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; \
	done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing: $$missing"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing >/dev/null; \
	fi

build: deps
	@if [ ! -f $(BUILD)/build.ninja ]; then \
	  cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) \
	    -DCMAKE_CXX_COMPILER_LAUNCHER=ccache; \
	fi
	cmake --build $(BUILD) -j $(JOBS)

# The plain suite: unit, end-to-end, physics and editor tests (a few minutes on 2 cores).
test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE 'fuzz|sanitize|format'

# Everything CI runs: the plain suite, then the format check, a short fuzzing campaign and the
# runtime's tests rebuilt under ASan/UBSan and TSan (each sanitizer in a build tree of its own).
check: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE 'fuzz|sanitize|format'
	cd $(BUILD) && ctest --output-on-failure -L 'format|fuzz|sanitize'

# Rewrites every C++ source in place to follow .clang-format.
format:
	tests/format/check_format.sh $(CURDIR) --fix

# What `make demo` adds: an encoder for the video (without it the viewer writes PNG frames).
DEMO_PACKAGES := ffmpeg

demo: build
	@missing=$$(for p in $(DEMO_PACKAGES); do \
	  dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; \
	done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing: $$missing"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing >/dev/null \
	    || echo "could not install $$missing: the demo writes PNG frames instead of a video"; \
	fi
	@rm -rf out/demo && mkdir -p out/demo
	cd out/demo && $(abspath $(BUILD))/bin/vrflow run $(CURDIR)/examples/paper_scene/paper_scene_fluid.xml \
	  --iterations 300 --no-progress --report report.json --set water.surface=on
	@cd out/demo && if [ -f demo.mp4 ]; then \
	  ffmpeg -loglevel error -y -sseof -0.2 -i demo.mp4 -frames:v 1 -update 1 frame.png; \
	else cp "$$(ls demo_*.png | tail -1)" frame.png; fi
	@QT_QPA_PLATFORM=offscreen $(BUILD)/bin/vrflow-editor examples/paper_scene/paper_scene_fluid.xml \
	  --screenshot out/demo/editor.png >/dev/null 2>&1 || echo "(no editor screenshot)"
	@echo "demo results in out/demo/: $$(cd out/demo && ls demo.mp4 2>/dev/null || echo PNG frames), frame.png, editor.png, report.json"

# Installs the build into PREFIX (default /usr/local): programs, libraries, the SDK's headers, the
# node packages, schemas, the CMake and pkg-config files (docs/install.md).
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

clean:
	rm -rf $(BUILD) out
