/* The table of one compiled copy of the model, for one instruction set.
 *
 * The build compiles the model's units (stewart_model*.c) and this file once per target,
 * with that target's flags and
 *   -DSTEWART_TARGET=<name>              the table's name: stewart_table_<name>
 *   -DSTEWART_TARGET_LEVEL="<level>"     the x86-64 level the CPU must have ("" for none)
 *   -DSTEWART_TARGET_FLAGS="<flags>"     the flags, for build_info
 *   -DSTEWART_PREFIX=<prefix>            (all copies but one) the copy's functions are
 *                                        named <prefix>_<name>, so the copies link together.
 */
#define STEWART_STRING_(a) #a
#define STEWART_STRING(a) STEWART_STRING_(a)
#if defined(__clang__)
#define STEWART_COMPILER "clang " __VERSION__
#elif defined(__GNUC__)
#define STEWART_COMPILER "gcc " __VERSION__
#else
#define STEWART_COMPILER "unknown compiler"
#endif

#include "stewart_internal.h"
#include "stewart_dispatch.h"

/* The public functions in the convention of the table's `call` (stewart_call): each its batch
 * function, its arrays passed from in[] and out[]. */
@CALLS@
const stewart_table STEWART_JOIN(stewart_table, STEWART_TARGET) = {
    STEWART_STRING(STEWART_TARGET), STEWART_TARGET_LEVEL, STEWART_TARGET_FLAGS, STEWART_COMPILER,
@ENTRIES@
};
