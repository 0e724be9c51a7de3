/* Refuses, before any of the program's own code runs, a CPU that lacks an
 * instruction set extension this build of animats was compiled to use
 * (`.cargo/config.toml` builds for x86-64-v3: AVX2, FMA, BMI2), with a
 * message that names what is missing and how to build for this CPU,
 * instead of dying later on an illegal instruction.
 *
 * Compiled by build.rs for the baseline x86-64 (no AVX), and run as a
 * constructor: it executes before Rust's `main` and before the Python
 * module's initialisation, whose code may use any of those instructions.
 * build.rs defines ANIMATS_CHECKS as one CHECK("name") for each feature
 * rustc was told to use, in GCC's names ("bmi" for rustc's "bmi1").
 * ANIMATS_TEST_CPU_LACKS (a comma-separated list of those names) makes it
 * act as if this CPU lacked them: the tests' way to see the refusal on a
 * CPU that has everything. */

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int pretends_to_lack(const char *name) {
    const char *list = getenv("ANIMATS_TEST_CPU_LACKS");
    size_t n = strlen(name);
    while (list && *list) {
        const char *end = strchr(list, ',');
        size_t len = end ? (size_t)(end - list) : strlen(list);
        if (len == n && strncmp(list, name, n) == 0) {
            return 1;
        }
        list = end ? end + 1 : NULL;
    }
    return 0;
}

static void say(const char *s) {
    ssize_t ignored = write(2, s, strlen(s));
    (void)ignored;
}

static char missing[160];

static void lacks(const char *name) {
    if (missing[0] != '\0') {
        strcat(missing, ", ");
    }
    strcat(missing, name);
}

/* __builtin_cpu_supports takes a string literal: hence a macro. */
#define CHECK(name)                                                          \
    if (!__builtin_cpu_supports(name) || pretends_to_lack(name)) {           \
        lacks(name);                                                         \
    }

__attribute__((constructor)) void animats_cpu_check(void) {
    __builtin_cpu_init();
    ANIMATS_CHECKS
    if (missing[0] != '\0') {
        say("error: this build of animats uses instructions this CPU does not have (");
        say(missing);
        say(").\nBuild it for this CPU instead:\n"
            "    RUSTFLAGS=\"-C target-cpu=native\" cargo build --release -p animats\n"
            "(README.md, \"Building for another CPU\").\n");
        _exit(2);
    }
}
