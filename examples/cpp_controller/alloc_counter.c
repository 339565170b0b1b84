/* alloc_counter.c -- an interposed allocator that counts heap allocations (glibc), for the
 * example's check that its loop allocates nothing: LD_PRELOAD=liballoc_counter.so counts every
 * malloc, calloc, realloc and aligned allocation of the process (operator new's included) and
 * passes it on to glibc's own; alloc_counter_total() tells the count. */
#include <stddef.h>

extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t count, size_t size);
extern void *__libc_realloc(void *pointer, size_t size);
extern void *__libc_memalign(size_t alignment, size_t size);

static unsigned long total;

static void counted(void)
{
    __atomic_add_fetch(&total, 1, __ATOMIC_RELAXED);
}

unsigned long alloc_counter_total(void)
{
    return __atomic_load_n(&total, __ATOMIC_RELAXED);
}

void *malloc(size_t size)
{
    counted();
    return __libc_malloc(size);
}

void *calloc(size_t count, size_t size)
{
    counted();
    return __libc_calloc(count, size);
}

void *realloc(void *pointer, size_t size)
{
    counted();
    return __libc_realloc(pointer, size);
}

void *memalign(size_t alignment, size_t size)
{
    counted();
    return __libc_memalign(alignment, size);
}

void *aligned_alloc(size_t alignment, size_t size)
{
    counted();
    return __libc_memalign(alignment, size);
}

int posix_memalign(void **pointer, size_t alignment, size_t size)
{
    counted();
    *pointer = __libc_memalign(alignment, size);
    return *pointer ? 0 : 12; /* ENOMEM */
}
