# SPDX-License-Identifier: Apache-2.0
# The stm32f4 port's ARM images; included by firmware/Makefile and run from firmware/.
#   make -C firmware arm    real STM32F407 board image: build/arm/wirefish.{elf,bin}
#   make -C firmware qemu   emulator image (-M netduinoplus2): build/qemu/wirefish.elf
# Inputs from the including Makefile (set before the include): CORE_SRCS, the core's C files
# (relative to firmware/), CORE_INCLUDES (default -Iinclude) and WARNINGS (the core's warning
# flags, errors included; default -Wall -Wextra -Werror). Each link prints flash and RAM use
# and fails beyond the budget: 32 KB flash, 8 KB RAM (the stack's 2 KB included).

STM32F4_DIR := port/stm32f4
ARM_PREFIX ?= arm-none-eabi-
ARM_CC := $(ARM_PREFIX)gcc
ARM_SIZE := $(ARM_PREFIX)size
ARM_OBJCOPY := $(ARM_PREFIX)objcopy
ARM_BUILD ?= build
ARM_FLASH_BUDGET := 32768
ARM_RAM_BUDGET := 8192
ARM_ARCH := -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard
CORE_INCLUDES ?= -Iinclude
WARNINGS ?= -Wall -Wextra -Werror -Wundef
ARM_CFLAGS := $(ARM_ARCH) -std=c11 -Os -g $(WARNINGS) -ffunction-sections \
	-fdata-sections $(CORE_INCLUDES) -I$(STM32F4_DIR)
ARM_LDFLAGS := $(ARM_ARCH) --specs=nano.specs --specs=nosys.specs -nostartfiles \
	-T$(STM32F4_DIR)/stm32f4.ld -Wl,--gc-sections
ARM_PORT_SRCS := $(wildcard $(STM32F4_DIR)/*.c)
# The emulator's test console: only the QEMU image links it (debug_console.h).
ARM_TEST_SRCS := $(STM32F4_DIR)/debug_console.c

.PHONY: arm qemu arm-toolchain
arm: $(ARM_BUILD)/arm/wirefish.elf $(ARM_BUILD)/arm/wirefish.bin
	@$(call ARM_BUDGET,arm,$<)
qemu: $(ARM_BUILD)/qemu/wirefish.elf
	@$(call ARM_BUDGET,qemu,$<)

# Prints an image's flash (text + data) and RAM (data + bss + stack) use; fails beyond budget.
ARM_BUDGET = set -- $$($(ARM_SIZE) -B $(2) | awk 'NR == 2 {print $$1 + $$2, $$2 + $$3}'); \
	echo "firmware $(1): flash $$1 B of $(ARM_FLASH_BUDGET), RAM $$2 B of $(ARM_RAM_BUDGET)" \
	  "(stack included): $(2)"; \
	if [ "$$1" -gt $(ARM_FLASH_BUDGET) ] || [ "$$2" -gt $(ARM_RAM_BUDGET) ]; then \
	  echo "firmware $(1): over budget" >&2; exit 1; fi

arm-toolchain:
	@command -v $(ARM_CC) >/dev/null 2>&1 || { echo "firmware: $(ARM_CC) not found: run" \
	  "'make setup' as root (it installs it with apt), or install gcc-arm-none-eabi and" \
	  "libnewlib-arm-none-eabi" >&2; exit 1; }

# One variant: $(1) its name (the build directory), $(2) its defines (WF_PORT_QEMU always
# defined: -Wundef), $(3) its port sources.
define ARM_VARIANT
$(1)_OBJS := $$(patsubst %.c,$(ARM_BUILD)/$(1)/obj/%.o,$(3) $(CORE_SRCS))
$(ARM_BUILD)/$(1)/obj/%.o: %.c | arm-toolchain
	@mkdir -p $$(@D)
	$(ARM_CC) $(ARM_CFLAGS) $(2) -MMD -MP -c $$< -o $$@
$(ARM_BUILD)/$(1)/wirefish.elf: $$($(1)_OBJS) $(STM32F4_DIR)/stm32f4.ld
	$(ARM_CC) $(ARM_LDFLAGS) -Wl,-Map=$(ARM_BUILD)/$(1)/wirefish.map -o $$@ $$($(1)_OBJS) -lm
-include $$($(1)_OBJS:.o=.d)
endef

$(eval $(call ARM_VARIANT,arm,-DWF_PORT_QEMU=0,$(filter-out $(ARM_TEST_SRCS),$(ARM_PORT_SRCS))))
$(eval $(call ARM_VARIANT,qemu,-DWF_PORT_QEMU=1,$(ARM_PORT_SRCS)))

$(ARM_BUILD)/arm/wirefish.bin: $(ARM_BUILD)/arm/wirefish.elf
	$(ARM_OBJCOPY) -O binary $< $@
