/*
 * atomic_file.c - temporary file + rename, see atomic_file.h.
 *
 * While temporaries are open, SIGTERM, SIGINT and SIGHUP whose disposition is the default
 * (ending the process) are caught by a handler that unlinks every open temporary, whose
 * path was copied into a static slot before the file was created, then restores the
 * default action and raises the signal again: the process still ends by that signal, and
 * leaves no "<path>.tmp-<pid>" behind. unlink, sigaction and raise are async-signal-safe.
 * A signal the program handles itself (the CLI's Ctrl-C during a hierarchical solve) is
 * left to its handler. When the last temporary is committed or aborted the default
 * action comes back.
 */
#include "core/atomic_file.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"

/* Temporaries open at once (the lit mesh's .obj and .mtl, say); more are written without
 * the signal cleanup. */
#define ATOMIC_SLOTS 8

static const int cleanup_signals[] = {SIGTERM, SIGINT, SIGHUP};
#define CLEANUP_SIGNAL_COUNT (sizeof(cleanup_signals) / sizeof(cleanup_signals[0]))

static char slot_path[ATOMIC_SLOTS][sizeof(((rad_atomic_file *)0)->temp_path)];
static volatile sig_atomic_t slot_used[ATOMIC_SLOTS];
static pthread_mutex_t slot_lock = PTHREAD_MUTEX_INITIALIZER;
static int slots_open;                                 /* under slot_lock */
static bool handler_installed[CLEANUP_SIGNAL_COUNT]; /* under slot_lock */

static void remove_temporaries_and_reraise(int signal_number)
{
    int saved = errno;
    for (int k = 0; k < ATOMIC_SLOTS; k++)
        if (slot_used[k])
            unlink(slot_path[k]);
    struct sigaction default_action;
    memset(&default_action, 0, sizeof(default_action));
    default_action.sa_handler = SIG_DFL;
    sigemptyset(&default_action.sa_mask);
    sigaction(signal_number, &default_action, NULL);
    errno = saved;
    raise(signal_number); /* delivered when this handler returns: the process ends */
}

/* Registers a temporary path for the signal cleanup; returns its slot, or -1. */
static int slot_take(const char *temp_path)
{
    int slot = -1;
    pthread_mutex_lock(&slot_lock);
    for (int k = 0; k < ATOMIC_SLOTS && slot < 0; k++)
        if (!slot_used[k])
            slot = k;
    if (slot >= 0) {
        strcpy(slot_path[slot], temp_path);
        atomic_signal_fence(memory_order_seq_cst); /* the path is whole before it is used */
        slot_used[slot] = 1;
        if (slots_open++ == 0)
            for (size_t s = 0; s < CLEANUP_SIGNAL_COUNT; s++) {
                struct sigaction current, cleanup;
                handler_installed[s] = false;
                if (sigaction(cleanup_signals[s], NULL, &current) != 0 ||
                    (current.sa_flags & SA_SIGINFO) || current.sa_handler != SIG_DFL)
                    continue;
                memset(&cleanup, 0, sizeof(cleanup));
                cleanup.sa_handler = remove_temporaries_and_reraise;
                sigfillset(&cleanup.sa_mask); /* one handler at a time */
                handler_installed[s] = sigaction(cleanup_signals[s], &cleanup, NULL) == 0;
            }
    }
    pthread_mutex_unlock(&slot_lock);
    return slot;
}

/* The temporary is renamed or removed: no cleanup for it any more. */
static void slot_release(int slot)
{
    if (slot < 0)
        return;
    pthread_mutex_lock(&slot_lock);
    slot_used[slot] = 0;
    if (--slots_open == 0)
        for (size_t s = 0; s < CLEANUP_SIGNAL_COUNT; s++) {
            struct sigaction current;
            if (handler_installed[s] && sigaction(cleanup_signals[s], NULL, &current) == 0 &&
                current.sa_handler == remove_temporaries_and_reraise) {
                struct sigaction default_action;
                memset(&default_action, 0, sizeof(default_action));
                default_action.sa_handler = SIG_DFL;
                sigemptyset(&default_action.sa_mask);
                sigaction(cleanup_signals[s], &default_action, NULL);
            }
            handler_installed[s] = false;
        }
    pthread_mutex_unlock(&slot_lock);
}

rad_status rad_atomic_open(rad_atomic_file *file, const char *path, rad_error *error)
{
    memset(file, 0, sizeof(*file));
    file->slot = -1;
    if (strlen(path) >= sizeof(file->final_path))
        return rad_fail(error, RAD_ERR_INVALID, "%s: path too long", path);
    strcpy(file->final_path, path);
    snprintf(file->temp_path, sizeof(file->temp_path), "%s.tmp-%ld", path, (long)getpid());
    file->slot = slot_take(file->temp_path); /* before the file exists */
    file->stream = fopen(file->temp_path, "wb");
    if (!file->stream) {
        int saved = errno;
        slot_release(file->slot);
        file->slot = -1;
        return rad_fail(error, RAD_ERR_IO, "%s: cannot write: %s", path, strerror(saved));
    }
    return RAD_OK;
}

rad_status rad_atomic_commit(rad_atomic_file *file, rad_error *error)
{
    int failed = ferror(file->stream) != 0;
    int saved = errno;
    if (fclose(file->stream) != 0 && !failed) {
        failed = 1;
        saved = errno;
    }
    file->stream = NULL;
    if (failed) {
        remove(file->temp_path);
        slot_release(file->slot);
        file->slot = -1;
        return rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", file->final_path,
                        strerror(saved));
    }
    if (rename(file->temp_path, file->final_path) != 0) {
        saved = errno;
        remove(file->temp_path);
        slot_release(file->slot);
        file->slot = -1;
        return rad_fail(error, RAD_ERR_IO, "%s: cannot write: %s", file->final_path,
                        strerror(saved));
    }
    slot_release(file->slot);
    file->slot = -1;
    return RAD_OK;
}

void rad_atomic_abort(rad_atomic_file *file)
{
    if (file->stream) {
        fclose(file->stream);
        file->stream = NULL;
        remove(file->temp_path);
        slot_release(file->slot);
        file->slot = -1;
    }
}

rad_status rad_write_file_atomic(const char *path, const void *data, size_t size,
                                 rad_error *error)
{
    rad_atomic_file file;
    rad_status status = rad_atomic_open(&file, path, error);
    if (status != RAD_OK)
        return status;
    if (size && fwrite(data, 1, size, file.stream) != size) {
        int saved = errno;
        rad_atomic_abort(&file);
        return rad_fail(error, RAD_ERR_IO, "%s: write failed: %s", path, strerror(saved));
    }
    return rad_atomic_commit(&file, error);
}
