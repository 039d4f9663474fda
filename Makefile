# argil — the one entry point. See README.md.
#   make / make all   build everything (release flags) and check the freestanding parts
#   make run          install missing packages, build, run the default sculpting session
#   make test         unit + SIL tests under ASan/UBSan, and file checks; ends with a summary
#   make fuzz         every libFuzzer target for FUZZ_SECONDS (default 60) each
#   make bench        figures for the 1 kHz path and the host
#   make cross / hil  later targets (see their messages)
#   make clean

BUILD ?= build
CC ?= gcc
FUZZ_SECONDS ?= 60
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
LDLIBS := -lm

SHARED_SRC := $(wildcard shared/*.c)
CORE_SRC := $(wildcard firmware/core/*.c)
HAL_SIM_SRC := firmware/hal/hal_sim.c
SIM_SRC := $(wildcard sim/*.c)
HOST_SRC := $(filter-out host/app/main.c,$(wildcard host/*/*.c))
LIB_SRC := $(SHARED_SRC) $(CORE_SRC) $(wildcard $(HAL_SIM_SRC)) $(SIM_SRC) $(HOST_SRC)
RT_SRC := $(SHARED_SRC) $(CORE_SRC)

UNIT_TESTS := $(patsubst tests/unit/%.c,%,$(wildcard tests/unit/test_*.c))
SIL_TESTS := $(patsubst tests/sil/%.c,%,$(wildcard tests/sil/test_*.c))
FUZZ_TARGETS := $(patsubst tests/fuzz/%.c,%,$(wildcard tests/fuzz/fuzz_*.c))

REL := $(BUILD)/rel
SAN := $(BUILD)/san
FZ := $(BUILD)/fuzz

.PHONY: all run test fuzz bench cross hil clean deps deps-build deps-test deps-fuzz check-freestanding tests-build
.DEFAULT_GOAL := all

all: $(REL)/argil check-freestanding

deps:
	@sh toolchain/install-deps.sh

deps-build:
	@sh toolchain/install-deps.sh build

deps-test:
	@sh toolchain/install-deps.sh test

deps-fuzz:
	@sh toolchain/install-deps.sh fuzz

# Pattern rules: release and sanitizer objects.
$(REL)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(REL_CFLAGS) $(if $(filter $<,$(RT_SRC)),$(RT_FLAGS)) -MMD -MP -c $< -o $@

$(SAN)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) $(if $(filter $<,$(RT_SRC)),$(RT_FLAGS)) -MMD -MP -c $< -o $@

$(REL)/libargil.a: $(LIB_SRC:%.c=$(REL)/%.o)
	@rm -f $@
	ar rcs $@ $^

$(SAN)/libargil.a: $(LIB_SRC:%.c=$(SAN)/%.o)
	@rm -f $@
	ar rcs $@ $^

$(REL)/argil: $(REL)/host/app/main.o $(REL)/libargil.a
	$(CC) $(REL_CFLAGS) $^ -o $@ $(LDLIBS)

$(SAN)/argil: $(SAN)/host/app/main.o $(SAN)/libargil.a
	$(CC) $(TEST_CFLAGS) $^ -o $@ $(LDLIBS)

$(SAN)/tests/%: tests/unit/%.c $(SAN)/libargil.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) $< $(SAN)/libargil.a -o $@ -lcmocka $(LDLIBS)

$(SAN)/sil/%: tests/sil/%.c $(SAN)/libargil.a
	@mkdir -p $(dir $@)
	$(CC) $(TEST_CFLAGS) $< $(SAN)/libargil.a -o $@ -lcmocka $(LDLIBS)

# The real-time parts must not reach the heap, stdio or blocking calls: link them into one
# relocatable object and list what they still need from outside.
check-freestanding: $(RT_SRC:%.c=$(REL)/%.o)
	@sh toolchain/check-freestanding.sh $^

tests-build: $(UNIT_TESTS:%=$(SAN)/tests/%) $(SIL_TESTS:%=$(SAN)/sil/%) $(SAN)/argil $(REL)/argil

test: deps-test
	@$(MAKE) --no-print-directory tests-build check-freestanding
	@sh tests/run_all.sh $(SAN) $(REL)

run: deps-build
	@$(MAKE) --no-print-directory all
	$(REL)/argil sculpt --device sim --script $(SCRIPT) --out $(OUT)

# libFuzzer targets: clang, the same library sources compiled with the fuzzer's sanitizers.
FUZZ_CFLAGS := $(CSTD) $(INC) -g -O1 -fsanitize=fuzzer,address,undefined
$(FZ)/%: tests/fuzz/%.c $(LIB_SRC)
	@mkdir -p $(dir $@)
	clang $(FUZZ_CFLAGS) $< $(LIB_SRC) -o $@ $(LDLIBS)

fuzz: deps-fuzz
	@$(MAKE) --no-print-directory $(FUZZ_TARGETS:%=$(FZ)/%)
	@for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(FZ)/corpus/$$t; \
	  seeds=tests/fuzz/corpus/$$t; [ -d $$seeds ] || seeds=; \
	  echo "fuzz: $$t for $(FUZZ_SECONDS) s"; \
	  $(FZ)/$$t -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 \
	     $(FZ)/corpus/$$t $$seeds >$(FZ)/$$t.log 2>&1; st=$$?; \
	  grep -E '^(Done|stat::(number_of_executed_units|new_units_added|peak_rss_mb))' $(FZ)/$$t.log; \
	  if [ $$st != 0 ]; then tail -n 40 $(FZ)/$$t.log; echo "fuzz: $$t FAILED (log: $(FZ)/$$t.log)"; exit 1; fi; \
	done

bench: all
	@sh tests/bench.sh $(REL)

cross:
	@echo "make cross: the aarch64 board daemon and the Cortex-M image come with the board issue;"
	@echo "            today 'make all' already proves the core links without heap or stdio."

hil:
	@echo "make hil: the VM rig with real vcan/gpio-sim/FunctionFS comes with the HIL issue."

clean:
	rm -rf $(BUILD) $(OUT)

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
