/* The compiled copies of the model and the choice between them at run time
 * (codegen/templates/dispatch/dispatch.h, copied verbatim by the generator after the table of
 * stewart_dispatch.h).
 *
 * The build compiles stewart_target.c once per target, each copy with its own instruction
 * set, and lists the copies in STEWART_TABLES, an X-macro: X(baseline) X(avx2) X(avx512).
 * A target needs a CPU level (STEWART_CPU_LEVELS: the compiler knows the x86-64 levels
 * of __builtin_cpu_supports); without it, only the copy that runs everywhere is listed.
 * Only the module that chooses defines STEWART_TABLES. */
#ifdef STEWART_TABLES
#include <stddef.h>
#include <string.h>

#define X(name) extern const stewart_table stewart_table_##name;
STEWART_TABLES
#undef X

/* The compiled copies, the one that runs everywhere first; NULL-terminated. */
#define X(name) &stewart_table_##name,
static const stewart_table *const stewart_tables[] = {STEWART_TABLES NULL};
#undef X

/* 1 if this CPU runs code for the x86-64 level `level` ("" runs everywhere), else 0. */
static int stewart_cpu_supports(const char *level)
{
    if (level[0] == '\0') {
        return 1;
    }
#ifdef STEWART_CPU_LEVELS
    __builtin_cpu_init();
    if (strcmp(level, "x86-64-v2") == 0) {
        return __builtin_cpu_supports("x86-64-v2") != 0;
    }
    if (strcmp(level, "x86-64-v3") == 0) {
        return __builtin_cpu_supports("x86-64-v3") != 0;
    }
    if (strcmp(level, "x86-64-v4") == 0) {
        return __builtin_cpu_supports("x86-64-v4") != 0;
    }
#endif
    return 0;
}
#endif /* STEWART_TABLES */

/* 1 if the batches run on OpenMP threads (the build found OpenMP), else 0. */
#ifdef _OPENMP
#define STEWART_OPENMP 1
#else
#define STEWART_OPENMP 0
#endif
