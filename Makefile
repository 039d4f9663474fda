# argil — the one entry point. See README.md.
#   make / make all   build everything (release flags) and check the freestanding parts
#   make run          install missing packages, build, run the default sculpting session
#   make test         every tier below (CI); ends with "N passed, N failed, N skipped"
#   make unit         cmocka unit tests under ASan/UBSan, and the test runner's own test
#   make sil          the SIL scenarios under ASan/UBSan (lockstep, virtual clock)
#   make sys          tests/sys: the programs and their files (not cross, not hil)
#   make fuzz         every libFuzzer target for FUZZ_SECONDS (default 60) each
#   make fuzz-long    every libFuzzer target to FUZZ_RUNS (default 10^7) executions
#   make bench        figures for the 1 kHz path and the host
#   make cross        aarch64 and Cortex-M builds, run under qemu (docs/board.md)
#   make hil          the HIL VM rig: real argil-board on vcan/gpio-sim/FunctionFS (hil/README.md)
#   make hil-repeat N=20  the HIL plan N times: each check's passes of N (hil/repeat.sh)
#   make clean

BUILD ?= build
CC ?= gcc
FUZZ_SECONDS ?= 60
FUZZ_RUNS ?= 10000000
FUZZ_LONG_MAX_S ?= 14400
OUT ?= out
SCRIPT ?= scripts/default.scn

WARN := -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes -Wmissing-prototypes \
        -Wpointer-arith -Wformat=2 -Wno-format-truncation
# firmware/core and shared/: no variable-length arrays, nothing from the hosted libc.
RT_FLAGS := -Wvla -fno-common
CSTD := -std=c11 -D_DEFAULT_SOURCE
INC := -I.

REL_CFLAGS := $(CSTD) $(WARN) $(INC) -O2 -g
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
TEST_CFLAGS := $(CSTD) $(WARN) $(INC) -O1 -g $(SAN_FLAGS)
# libsodium: the UDP link's keyed BLAKE2b tags, nonces and key wiping, supplied to the envelope
# in shared/link_envelope.c by each side (firmware/hal/link_auth.c, host/link/link_crypto.c;
# docs/link.md "Link key"); never in firmware/core or shared/.
LDLIBS := -lsodium -lm

SHARED_SRC := $(wildcard shared/*.c)
CORE_SRC := $(wildcard firmware/core/*.c)
HAL_SIM_SRC := firmware/hal/hal_sim.c firmware/hal/link_bind.c
SIM_SRC := $(wildcard sim/*.c)
# The lockstep rig (sim/rig/rig.h): the simulated arm, the sim HAL and the board core together.
RIG_SRC := $(wildcard sim/rig/*.c)
# host/: model/ (representations) <- solve/ (the global solve) <- app/, with mesh/ io/ fit/ render/ link/.
HOST_SRC := $(filter-out host/app/main.c,$(wildcard host/*/*.c))
# The board's libsodium and key-file reading for the UDP link (the envelope and the key file's
# rules are shared/; the host's side is host/link/); in LIB_SRC too, for the unit tests.
LINK_AUTH_SRC := firmware/hal/link_auth.c firmware/hal/link_key.c
LIB_SRC := $(SHARED_SRC) $(CORE_SRC) $(wildcard $(HAL_SIM_SRC)) $(LINK_AUTH_SRC) $(SIM_SRC) $(RIG_SRC) $(HOST_SRC)
RT_SRC := $(SHARED_SRC) $(CORE_SRC)
# bus/: hosted Linux access to a real CAN bus (SocketCAN) and GPIO chip (libgpiod), for the
# board daemon's HAL and for argil-sim, which plays the drives on such a bus.
BUS_SRC := $(wildcard bus/*.c)
# argil-board, the Linux board daemon: the core, the simulated arm (its --bus sim), the Linux
# HAL (SocketCAN and libgpiod through bus/, UDP/FunctionFS link) and firmware/board/.
BOARD_HAL_SRC := firmware/hal/hal_linux.c firmware/hal/hal_sim_bus.c firmware/hal/gpio_port.c \
                 firmware/hal/link_udp.c firmware/hal/link_bind.c firmware/hal/link_ffs.c \
                 $(BUS_SRC) $(LINK_AUTH_SRC)
BOARD_SRC := $(filter-out firmware/board/main.c,$(wildcard firmware/board/*.c)) $(BOARD_HAL_SRC)
BOARD_LIB_SRC := $(SHARED_SRC) $(CORE_SRC) $(SIM_SRC) $(BOARD_SRC)
# libinih (Debian's libinih-dev): reads argil-board's INI file, under the rules board_config.c
# adds (docs/board.md, "The configuration file"); every link of board_config.o needs it.
INI_LDLIBS := -linih
BOARD_LDLIBS := -lgpiod -lsodium $(INI_LDLIBS) -lpthread -lm
# Sources a fuzz target may need beyond LIB_SRC (the board's config parser: libinih, no libgpiod).
FUZZ_EXTRA_SRC := firmware/board/board_config.c bus/gpio_names.c

UNIT_TESTS := $(patsubst tests/unit/%.c,%,$(wildcard tests/unit/test_*.c))
SIL_TESTS := $(patsubst tests/sil/%.c,%,$(wildcard tests/sil/test_*.c))
FUZZ_TARGETS := $(patsubst tests/fuzz/%.c,%,$(wildcard tests/fuzz/fuzz_*.c))

REL := $(BUILD)/rel
SAN := $(BUILD)/san
FZ := $(BUILD)/fuzz

.PHONY: all check-compile-deps check-layers check-function-length run test unit sil sys fuzz fuzz-long fuzz-build bench cross hil hil-repeat clean deps deps-build deps-test deps-bench deps-fuzz deps-cross deps-hil check-freestanding tests-build cross-build
.DEFAULT_GOAL := all

all: $(REL)/argil $(REL)/argil-board check-freestanding check-layers check-function-length

# A fresh machine gets one clear line instead of a compiler's "sodium.h: No such file".
check-compile-deps:
	@sh toolchain/install-deps.sh --check compile >/dev/null || { \
	  echo "argil: missing Debian packages:$$(sh toolchain/install-deps.sh --check compile | sed 's/^toolchain: missing://')"; \
	  echo "argil: install them with 'make deps-build' (as root), or use 'make run' / 'make test', which install what is missing"; \
	  exit 1; }

deps:
	@sh toolchain/install-deps.sh

deps-build:
	@sh toolchain/install-deps.sh build

deps-test:
	@sh toolchain/install-deps.sh test

deps-bench:
	@sh toolchain/install-deps.sh bench

deps-fuzz:
	@sh toolchain/install-deps.sh fuzz

deps-cross:
	@sh toolchain/install-deps.sh cross

deps-hil:
	@sh toolchain/install-deps.sh hil

# Pattern rules: release and sanitizer objects.
$(REL)/%.o: %.c | check-compile-deps
	@mkdir -p $(dir $@)
	$(CC) $(REL_CFLAGS) $(if $(filter $<,$(RT_SRC)),$(RT_FLAGS)) -MMD -MP -c $< -o $@

$(SAN)/%.o: %.c | check-compile-deps
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) $(if $(filter $<,$(RT_SRC)),$(RT_FLAGS)) -MMD -MP -c $< -o $@

$(REL)/libargil.a: $(LIB_SRC:%.c=$(REL)/%.o)
	@rm -f $@
	ar rcs $@ $^

$(SAN)/libargil.a: $(LIB_SRC:%.c=$(SAN)/%.o)
	@rm -f $@
	ar rcs $@ $^

$(REL)/libboard.a: $(BOARD_LIB_SRC:%.c=$(REL)/%.o)
	@rm -f $@
	ar rcs $@ $^

$(SAN)/libboard.a: $(BOARD_LIB_SRC:%.c=$(SAN)/%.o)
	@rm -f $@
	ar rcs $@ $^

# -z now: every library symbol is bound at start-up, so no tick of the real-time loop pays
# for the dynamic linker's first-call lookup (~200k instructions measured).
BOARD_LDFLAGS := -Wl,-z,now
$(REL)/argil-board: $(REL)/firmware/board/main.o $(REL)/libboard.a
	$(CC) $(REL_CFLAGS) $^ -o $@ $(BOARD_LDFLAGS) $(BOARD_LDLIBS)

$(SAN)/argil-board: $(SAN)/firmware/board/main.o $(SAN)/libboard.a
	$(CC) $(TEST_CFLAGS) $^ -o $@ $(BOARD_LDLIBS)

$(REL)/argil: $(REL)/host/app/main.o $(REL)/libargil.a
	$(CC) $(REL_CFLAGS) $^ -o $@ $(LDLIBS)

$(SAN)/argil: $(SAN)/host/app/main.o $(SAN)/libargil.a
	$(CC) $(TEST_CFLAGS) $^ -o $@ $(LDLIBS)

# A test is rebuilt when a header it includes changes (tests/sil/rig.h, rep_dent_sphere.h …): -MMD
# writes its .d into deps/ next to the binaries (not among them: the runner runs every test_* there),
# included at the end.
$(SAN)/tests/%: tests/unit/%.c $(SAN)/libargil.a
	@mkdir -p $(dir $@)deps
	$(CC) $(TEST_CFLAGS) -MMD -MP -MF $(dir $@)deps/$(notdir $@).d $< $(SAN)/libargil.a -o $@ -lcmocka $(LDLIBS)

# A UDP host for tests/sys/test_board_daemon.sh (the host's protocol peer over a real socket).
$(REL)/board_udp_client: tests/sys/board_udp_client.c $(REL)/libargil.a
	$(CC) $(REL_CFLAGS) $^ -o $@ $(LDLIBS)

# The HIL rig's tools (hil/README.md): timestamps and GPIO sampling; a minimal arming host.
$(REL)/hil-probe: hil/probe.c
	$(CC) $(REL_CFLAGS) $< -o $@

$(REL)/hil-host: hil/host_udp.c $(REL)/libargil.a
	$(CC) $(REL_CFLAGS) $^ -o $@ $(LDLIBS)

# argil-sim: the simulated arm on a SocketCAN bus and GPIO lines (docs/sim.md), with the
# board's own SocketCAN and GPIO wrappers; argil-hil-check: a scenario's expectations decided
# from a candump -l log and argil-sim's event log.
$(REL)/argil-sim: $(REL)/sim/app/argil_sim_main.o $(REL)/libboard.a
	$(CC) $(REL_CFLAGS) $^ -o $@ $(BOARD_LDLIBS)

$(REL)/argil-hil-check: $(REL)/sim/app/argil_hil_check_main.o $(REL)/libboard.a
	$(CC) $(REL_CFLAGS) $^ -o $@ $(LDLIBS)

all: $(REL)/argil-sim $(REL)/argil-hil-check
tests-build: $(REL)/argil-sim $(REL)/argil-hil-check

# Tests of the daemon and the Linux HAL link against the board library (no hal_sim.c).
$(SAN)/tests/test_board_%: tests/unit/test_board_%.c $(SAN)/libboard.a
	@mkdir -p $(dir $@)deps
	$(CC) $(TEST_CFLAGS) -MMD -MP -MF $(dir $@)deps/$(notdir $@).d $< $(SAN)/libboard.a -o $@ -lcmocka $(BOARD_LDLIBS)

$(SAN)/sil/%: tests/sil/%.c $(SAN)/libargil.a
	@mkdir -p $(dir $@)deps
	$(CC) $(TEST_CFLAGS) -MMD -MP -MF $(dir $@)deps/$(notdir $@).d $< $(SAN)/libargil.a -o $@ -lcmocka $(LDLIBS)

# The real-time parts must not reach the heap, stdio or blocking calls: link them into one
# relocatable object and list what they still need from outside.
check-freestanding: $(RT_SRC:%.c=$(REL)/%.o)
	@sh toolchain/check-freestanding.sh $^

# Includes keep DESIGN.md's layers: shared/ depends on nothing, host/ and firmware/ meet only
# in shared/, and only sim/rig/ puts firmware/, sim/ and the host link together.
check-layers:
	@sh toolchain/check-layers.sh

check-function-length:
	@sh toolchain/check-function-length.sh

tests-build: $(UNIT_TESTS:%=$(SAN)/tests/%) $(SIL_TESTS:%=$(SAN)/sil/%) $(SAN)/argil $(REL)/argil \
             $(SAN)/argil-board $(REL)/argil-board $(REL)/board_udp_client $(REL)/hil-probe $(REL)/hil-host

# Test tiers (README.md, "Tests"): each builds what it needs and runs through tests/run_all.sh,
# which counts every test and check and ends with "N passed, N failed, N skipped".
RUN_TESTS := sh tests/run_all.sh $(SAN) $(REL)
SYS_BINS := $(SAN)/argil $(REL)/argil $(SAN)/argil-board $(REL)/argil-board $(REL)/board_udp_client

test: deps-test deps-cross deps-hil
	@$(MAKE) --no-print-directory tests-build cross-build check-freestanding
	@$(RUN_TESTS) unit sil sys cross hil

unit: deps-test
	@$(MAKE) --no-print-directory $(UNIT_TESTS:%=$(SAN)/tests/%)
	@$(RUN_TESTS) unit

sil: deps-test
	@$(MAKE) --no-print-directory $(SIL_TESTS:%=$(SAN)/sil/%)
	@$(RUN_TESTS) sil

sys: deps-test
	@$(MAKE) --no-print-directory $(SYS_BINS) check-freestanding
	@$(RUN_TESTS) sys

run: deps-build
	@$(MAKE) --no-print-directory all
	$(REL)/argil sculpt --device sim --script $(SCRIPT) --out $(OUT)

# libFuzzer targets: clang. The library sources are compiled once, with the fuzzer's coverage
# instrumentation and sanitizers, into $(FZ)/libargil.a; each target compiles its own .c and
# links against it (-fsanitize=fuzzer adds libFuzzer's main at the link).
FUZZ_CC := clang
FUZZ_CFLAGS := $(CSTD) $(INC) -g -O1
FUZZ_LIB_SRC := $(LIB_SRC) $(FUZZ_EXTRA_SRC)
$(FZ)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link,address,undefined -MMD -MP -c $< -o $@

$(FZ)/libargil.a: $(FUZZ_LIB_SRC:%.c=$(FZ)/obj/%.o)
	@rm -f $@
	ar rcs $@ $^

$(FUZZ_TARGETS:%=$(FZ)/%): $(FZ)/%: tests/fuzz/%.c $(FZ)/libargil.a
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer,address,undefined -MMD -MP $< $(FZ)/libargil.a -o $@ $(LDLIBS) $(INI_LDLIBS)

fuzz-build: $(FUZZ_TARGETS:%=$(FZ)/%)

fuzz: deps-fuzz
	@$(MAKE) --no-print-directory fuzz-build
	@sh tests/fuzz.sh $(FZ) seconds $(FUZZ_SECONDS) $(FUZZ_TARGETS)

# Every target to FUZZ_RUNS executions, each cut at FUZZ_LONG_MAX_S; the table of counts goes
# to $(FZ)/fuzz-runs.md (docs/files.md, "Fuzzing").
fuzz-long: deps-fuzz
	@$(MAKE) --no-print-directory fuzz-build
	@sh tests/fuzz.sh $(FZ) runs $(FUZZ_RUNS) $(FUZZ_LONG_MAX_S) $(FUZZ_TARGETS)

bench: deps-bench
	@$(MAKE) --no-print-directory all
	@sh tests/bench.sh $(REL)

# ---- cross targets (docs/board.md) ----
# aarch64 Linux board: argil-board, the core's unit tests and one SIL scenario, run under
# qemu-aarch64 by tests/sys/test_cross.sh. Cortex-M: the core + shared/ as a bare-metal image
# that runs a fixed tick sequence (firmware/cortexm/) and reports through semihosting; built
# for Cortex-M4 (runs on qemu mps2-an386) and Cortex-M7 (mps2-an500). -ffp-contract=off keeps
# the MCU's fused multiply-adds from changing results against the host reference.
A64 := $(BUILD)/aarch64
A64_CC := aarch64-linux-gnu-gcc
A64_CFLAGS := $(CSTD) $(WARN) $(INC) -O2 -g
# The core's tests: test_safety_table is the full transition table, test_board_hal holds the
# SPSC ring's test (with the Linux HAL's), test_host_session the board's RT-stats message.
A64_UNIT := test_safety test_safety_table test_drives test_canopen test_board_hal test_host_session test_window test_arm_kin
A64_SIL := test_board_sim
A64_MISSING := $(filter-out $(UNIT_TESTS),$(A64_UNIT)) $(filter-out $(SIL_TESTS),$(A64_SIL))
$(if $(strip $(A64_MISSING)),$(error A64_UNIT/A64_SIL name no file in tests/unit or tests/sil: $(A64_MISSING)))
CM := $(BUILD)/cortexm
CM_CC := arm-none-eabi-gcc
CM_M4 := -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard
CM_M7 := -mcpu=cortex-m7 -mthumb -mfpu=fpv5-sp-d16 -mfloat-abi=hard
CM_CFLAGS := $(CSTD) $(WARN) $(INC) -O2 -g -ffunction-sections -fdata-sections -ffp-contract=off
CM_CORE_SRC := $(SHARED_SRC) $(filter-out firmware/core/board_hal.c,$(CORE_SRC))
CM_APP_SRC := firmware/cortexm/startup.c firmware/cortexm/tick_script.c firmware/cortexm/tick_main.c
# A reference to any of these from the core or shared/ becomes an undefined symbol: no link.
CM_FORBID := malloc free calloc realloc printf puts fopen
CM_REDEFINE := $(foreach f,$(CM_FORBID),--redefine-sym $(f)=argil_core_must_not_call_$(f))

$(A64)/%.o: %.c
	@mkdir -p $(dir $@)
	$(A64_CC) $(A64_CFLAGS) $(if $(filter $<,$(RT_SRC)),$(RT_FLAGS)) -MMD -MP -c $< -o $@

$(A64)/argil-board: $(A64)/firmware/board/main.o $(BOARD_LIB_SRC:%.c=$(A64)/%.o)
	$(A64_CC) $(A64_CFLAGS) $^ -o $@ $(BOARD_LDFLAGS) $(BOARD_LDLIBS)

$(A64)/tests/%: tests/unit/%.c $(LIB_SRC:%.c=$(A64)/%.o)
	@mkdir -p $(dir $@)
	$(A64_CC) $(A64_CFLAGS) $^ -o $@ -lcmocka $(LDLIBS)

# As on the host, tests of the daemon's Linux side link against the board's sources.
$(A64)/tests/test_board_%: tests/unit/test_board_%.c $(BOARD_LIB_SRC:%.c=$(A64)/%.o)
	@mkdir -p $(dir $@)
	$(A64_CC) $(A64_CFLAGS) $^ -o $@ -lcmocka $(BOARD_LDLIBS)

$(A64)/sil/%: tests/sil/%.c $(LIB_SRC:%.c=$(A64)/%.o)
	@mkdir -p $(dir $@)
	$(A64_CC) $(A64_CFLAGS) $^ -o $@ -lcmocka $(LDLIBS)

$(CM)/m4/%.o: %.c
	@mkdir -p $(dir $@)
	$(CM_CC) $(CM_M4) $(CM_CFLAGS) $(if $(filter $<,$(RT_SRC)),$(RT_FLAGS)) -MMD -MP -c $< -o $@

$(CM)/m7/%.o: %.c
	@mkdir -p $(dir $@)
	$(CM_CC) $(CM_M7) $(CM_CFLAGS) $(if $(filter $<,$(RT_SRC)),$(RT_FLAGS)) -MMD -MP -c $< -o $@

$(CM)/%/core.o: $(CM_CORE_SRC:%.c=$(CM)/m4/%.o) $(CM_CORE_SRC:%.c=$(CM)/m7/%.o)
	arm-none-eabi-ld -r -o $@.tmp $(CM_CORE_SRC:%.c=$(CM)/$*/%.o)
	arm-none-eabi-objcopy $(CM_REDEFINE) $@.tmp $@
	@rm -f $@.tmp

$(CM)/argil-%.elf: $(CM)/%/core.o $(CM_APP_SRC:%.c=$(CM)/m4/%.o) $(CM_APP_SRC:%.c=$(CM)/m7/%.o) firmware/cortexm/mps2.ld
	$(CM_CC) $(if $(filter m4,$*),$(CM_M4),$(CM_M7)) --specs=rdimon.specs -T firmware/cortexm/mps2.ld \
	    -Wl,--gc-sections $(CM_APP_SRC:%.c=$(CM)/$*/%.o) $(CM)/$*/core.o -lm -o $@

# The host reference of the same tick sequence, with the same float settings.
$(CM)/tick_ref: $(CM_APP_SRC:firmware/cortexm/startup.c=) $(CM_CORE_SRC)
	@mkdir -p $(dir $@)
	$(CC) $(REL_CFLAGS) -ffp-contract=off $(filter-out firmware/cortexm/startup.c,$(CM_APP_SRC)) $(CM_CORE_SRC) -o $@ $(LDLIBS)

.PRECIOUS: $(A64)/%.o $(CM)/m4/%.o $(CM)/m7/%.o $(CM)/%/core.o

cross-build: $(A64)/argil-board $(A64_UNIT:%=$(A64)/tests/%) $(A64_SIL:%=$(A64)/sil/%) \
             $(CM)/argil-m4.elf $(CM)/argil-m7.elf $(CM)/tick_ref

cross: deps-cross
	@$(MAKE) --no-print-directory cross-build $(REL)/board_udp_client
	@file $(A64)/argil-board | sed 's/, BuildID.*//'
	@arm-none-eabi-size $(CM)/argil-m4.elf $(CM)/argil-m7.elf
	@$(RUN_TESTS) cross

# The HIL rig (hil/README.md): Debian's kernel debs -> a qemu VM with vcan, gpio-sim and a
# FunctionFS gadget on dummy_hcd, the real argil-board in it; through tests/run_all.sh (each VM
# check one test), ends with "N passed, N failed, N skipped".
# argil-sim and argil-hil-check play hil/scenarios/*.scn in the VM; argil is the USB host.
HIL_BINS := $(REL)/argil-board $(REL)/board_udp_client $(REL)/hil-probe $(REL)/hil-host \
            $(REL)/argil-sim $(REL)/argil-hil-check $(REL)/argil
hil: deps-hil
	@$(MAKE) --no-print-directory $(HIL_BINS)
	@$(RUN_TESTS) hil

# The whole HIL plan N times over and each check's passes of N (hil/repeat.sh; not in make test).
N ?= 20
hil-repeat: deps-hil
	@sh hil/repeat.sh $(N) $(BUILD)

clean:
	rm -rf $(BUILD) $(OUT)

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
