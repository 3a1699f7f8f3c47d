/* libFuzzer target: fc_solve.c's FCLib HDF5 reader (fc_read on an HDF5 file). The
   bytes are written to a scratch file which fc_read opens; mutations of the seed files mostly
   change the datasets' values (sizes, pointers, indices, entries). As fc_solve runs it, libhdf5
   reads the file in a child process, so that its own faults on corrupted metadata are read
   errors; a fork per input makes that slow (about 600 inputs a second) and hides the reader's
   coverage from libFuzzer. Built with -DFC_HDF5_IN_PROCESS (make FUZZ_HDF5_IN_PROCESS=1) the
   reader runs in this process instead: 4 times the inputs a second, but a fault inside libhdf5
   then stops the run, and is ours only if fc_solve fails on the input too (fuzz/README.md).
   Leaks inside libhdf5 are suppressed and an oversized allocation request returns NULL (HDF5
   then reports an error). An accepted problem must be well formed (fc_fuzz_check.h); a
   rejected one must leave the problem empty with a message. */
#define FC_SOLVE_NO_MAIN
#include "fc_solve/fc_solve.c"

#include "fc_fuzz_check.h"

#include <stdint.h>
#include <unistd.h>

const char *__lsan_default_suppressions(void);
const char *__asan_default_options(void);

const char *__lsan_default_suppressions(void)
{
    return "leak:libhdf5\n";
}

const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

static char path[64];

static void remove_scratch(void)
{
    remove(path);
}

static const char *read_bytes_as_file(const uint8_t *data, size_t size, fc_problem *p)
{
    FILE *f;
    if (!path[0]) { /* one scratch file per process, in memory where /dev/shm exists (on a
                       disk, writing it took half the time) */
        int fd;
        strcpy(path, "/dev/shm/fuzz_fc_hdf5_XXXXXX");
        fd = mkstemp(path);
        if (fd < 0) {
            strcpy(path, "/tmp/fuzz_fc_hdf5_XXXXXX");
            fd = mkstemp(path);
        }
        if (fd < 0)
            abort();
        close(fd);
        atexit(remove_scratch);
    }
    f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
        abort();
    return fc_read(path, p);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fc_problem p;
    const char *err = read_bytes_as_file(data, size, &p);
    if (!err) {
        check_problem(&p);
        fc_free(&p);
    } else if (p.W || p.Wp || p.Wi || p.Wx || p.q || p.mu || !p.why[0]) {
        abort();
    }
    return 0;
}
