# vrflow: the four entry points. `make demo` and `make test` are all a new user needs.
SHELL := /bin/bash
BUILD ?= build
JOBS ?= $(shell nproc)
BUILD_TYPE ?= Release

# Every Debian package the project needs to build, test and benchmark.
PACKAGES := build-essential cmake ninja-build ccache pkg-config clang libclang-rt-14-dev \
  libgtest-dev libpugixml-dev libcli11-dev \
  nlohmann-json3-dev libxxhash-dev libzmq3-dev libopenmpi-dev openmpi-bin libxml2-utils procps \
  libbullet-dev libeigen3-dev libosmesa6-dev libpng-dev qt6-base-dev libgraphviz-dev \
  libsodium-dev openssh-server openssh-client

.PHONY: deps build test demo clean

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

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

demo: build
	@mkdir -p out/demo
	$(BUILD)/bin/vrflow run examples/pipeline/pipeline.xml --iterations 200 \
	  --report out/demo/report.json
	@echo "demo results in out/demo/"

clean:
	rm -rf $(BUILD) out
