/* SPDX-License-Identifier: Apache-2.0 */
/*
 * wirefish-fw-host: the firmware core as a virtual board on a pseudo-terminal (or on stdin and
 * stdout), with the wall clock as its millisecond clock. No servos move and no IMU is wired:
 * the IMU is synthetic (flagged IMU_FAULT) unless --imu none says absent.
 *
 *   wirefish-fw-host --pty [--link PATH]     prints "pty: /dev/pts/N" and serves it
 *   wirefish-fw-host                          frames on stdin/stdout (for a pipe or socat)
 *
 * The servo calibration's storage is a 16 KB unit in RAM, lost at exit, unless
 * --calibration-file PATH names a file: read at start (absent: an erased unit) and written
 * at each SERVO_TRIM SAVE or FACTORY, so a board started again on it boots on what was saved.
 */
#define _XOPEN_SOURCE 700
#define _DEFAULT_SOURCE

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "wf_host.h"

static volatile sig_atomic_t stop_requested;

static void on_signal(int signo)
{
    (void)signo;
    stop_requested = 1;
}

static uint32_t wall_millis(const struct timespec *start)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    const long long ms = (long long)(now.tv_sec - start->tv_sec) * 1000LL +
                         (now.tv_nsec - start->tv_nsec) / 1000000L;
    return (uint32_t)ms;
}

static int usage(const char *why)
{
    fprintf(stderr,
            "wirefish-fw-host: %s\n"
            "usage: wirefish-fw-host [--pty [--link PATH]] [--imu synthetic|none]\n"
            "                        [--command-timeout MS] [--heartbeat-timeout MS]\n"
            "                        [--calibration-file PATH]\n",
            why);
    return 2;
}

static int parse_ms(const char *text, uint32_t *out)
{
    char *end = NULL;
    const unsigned long value = strtoul(text, &end, 10);
    if (end == text || *end != '\0' || value == 0 || value >= 0x80000000ul) {
        return 0;
    }
    *out = (uint32_t)value;
    return 1;
}

static int open_pty(const char *link_path, int *keep_slave)
{
    const int master = posix_openpt(O_RDWR | O_NOCTTY);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
        perror("wirefish-fw-host: posix_openpt");
        return -1;
    }
    const char *name = ptsname(master);
    /* Hold the slave open: without it the master reads EIO between two hosts' sessions. */
    const int slave = open(name, O_RDWR | O_NOCTTY);
    struct termios tio;
    if (slave < 0 || tcgetattr(slave, &tio) != 0) {
        perror("wirefish-fw-host: pty");
        return -1;
    }
    cfmakeraw(&tio);
    tcsetattr(slave, TCSANOW, &tio);
    *keep_slave = slave;
    if (link_path != NULL) {
        unlink(link_path);
        if (symlink(name, link_path) != 0) {
            perror("wirefish-fw-host: symlink");
            return -1;
        }
    }
    printf("pty: %s\n", name);
    fflush(stdout);
    return master;
}

int main(int argc, char **argv)
{
    wf_config_t config;
    wf_config_defaults(&config);
    config.imu_mode = WF_IMU_SYNTHETIC;
    int use_pty = 0;
    const char *link_path = NULL;
    const char *calibration_path = NULL;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(arg, "--pty") == 0) {
            use_pty = 1;
        } else if (strcmp(arg, "--link") == 0 && value != NULL) {
            link_path = value;
            i++;
        } else if (strcmp(arg, "--calibration-file") == 0 && value != NULL) {
            calibration_path = value;
            i++;
        } else if (strcmp(arg, "--imu") == 0 && value != NULL) {
            if (strcmp(value, "synthetic") == 0) {
                config.imu_mode = WF_IMU_SYNTHETIC;
            } else if (strcmp(value, "none") == 0) {
                config.imu_mode = WF_IMU_MPU6050; /* no device model: probes NACK, IMU_FAULT */
            } else {
                return usage("--imu takes synthetic or none");
            }
            i++;
        } else if (strcmp(arg, "--command-timeout") == 0 && value != NULL) {
            if (!parse_ms(value, &config.command_timeout_ms)) {
                return usage("--command-timeout takes milliseconds, 1..2^31-1");
            }
            i++;
        } else if (strcmp(arg, "--heartbeat-timeout") == 0 && value != NULL) {
            if (!parse_ms(value, &config.heartbeat_timeout_ms)) {
                return usage("--heartbeat-timeout takes milliseconds, 1..2^31-1");
            }
            i++;
        } else {
            return usage("unknown or incomplete option");
        }
    }
    if (link_path != NULL && !use_pty) {
        return usage("--link needs --pty");
    }
    wf_host_storage_clear();
    if (calibration_path != NULL && !wf_host_storage_use_file(calibration_path)) {
        fprintf(stderr, "wirefish-fw-host: cannot read the calibration file %s\n",
                calibration_path);
        return 1;
    }
    int keep_slave = -1;
    const int in_fd = use_pty ? open_pty(link_path, &keep_slave) : STDIN_FILENO;
    const int out_fd = use_pty ? in_fd : STDOUT_FILENO;
    if (in_fd < 0) {
        return 1;
    }
    fcntl(out_fd, F_SETFL, fcntl(out_fd, F_GETFL) | O_NONBLOCK);
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGPIPE, SIG_IGN);

    struct timespec start;
    clock_gettime(CLOCK_MONOTONIC, &start);
    wf_host_reset();
    static wf_app_t app;
    wf_host_boot(); /* the port's start-up: a power-on reset, the I2C bus idle */
    wf_app_init(&app, &config);
    int input_open = 1;
    while (!stop_requested) {
        struct pollfd pfd = {.fd = in_fd, .events = POLLIN};
        const int ready = input_open ? poll(&pfd, 1, 1) : (usleep(1000), 0);
        if (ready > 0 && (pfd.revents & (POLLIN | POLLHUP))) {
            uint8_t buf[512];
            const ssize_t n = read(in_fd, buf, sizeof buf);
            if (n > 0) {
                wf_host_feed(buf, (size_t)n);
            } else if (n == 0 && !use_pty) {
                input_open = 0; /* stdin closed: keep serving stdout until a signal */
            }
        }
        wf_host_set_millis(wall_millis(&start));
        wf_app_poll(&app);
        uint8_t out[1024];
        size_t len;
        while ((len = wf_host_take_output(out, sizeof out)) > 0) {
            /* A full pty (nobody reading) drops the bytes, as a UART with no listener would. */
            if (write(out_fd, out, len) < 0 && errno != EAGAIN) {
                break;
            }
        }
    }
    if (link_path != NULL) {
        unlink(link_path);
    }
    if (keep_slave >= 0) {
        close(keep_slave);
    }
    return 0;
}
