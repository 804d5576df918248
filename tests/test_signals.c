/*
 * test_signals.c - SIGTERM, SIGINT or SIGHUP while the tool writes its output: the process
 * ends by that signal, the temporary "OUT.tmp-PID" is removed, and OUT keeps its old
 * content (the final file is never partial).
 *
 * The tool renders the Cornell box to a 2000 x 2000 PNG (zlib compression makes its write
 * last a good fraction of a second). The test watches the scratch folder with inotify and
 * sends the signal the moment the temporary is created, so the signal arrives during the
 * write without any sleep or timing. A run whose write finished first (OUT replaced)
 * proves nothing and is tried again; one in which the signal hit the write must leave OUT
 * as it was and no temporary.
 */
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include "testlib.h"

extern char **environ;

#define OLD_CONTENT "the previous output\n"

/* Runs the render, sends `signal_number` when "<output>.tmp-" appears. Returns 1 when the
 * signal hit the write (checked), 0 when the write was done first, -1 on a test failure. */
static int render_and_signal(int signal_number, const char *output)
{
    char temp_prefix[256];
    snprintf(temp_prefix, sizeof(temp_prefix), "%s.tmp-", output);
    test_write_file(output, OLD_CONTENT);
    int watch = inotify_init1(IN_CLOEXEC | IN_NONBLOCK);
    CHECK(watch >= 0);
    if (watch < 0)
        return -1;
    CHECK(inotify_add_watch(watch, test_tmpdir(), IN_CREATE) >= 0);

    char tool[] = RAD_TOOL, render[] = "render", dash_o[] = "-o", size[] = "--size",
         size_value[] = "2000x2000", spp[] = "--spp", one[] = "1", patch[] = "--patch-size",
         patch_value[] = "100", quiet[] = "--quiet";
    char out_path[4096];
    snprintf(out_path, sizeof(out_path), "%s", test_path(output));
    char *argv[] = {tool, render, dash_o, out_path, size, size_value, spp, one, patch,
                    patch_value, quiet, NULL};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, test_path("stderr.txt"),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    /* the default dispositions, whatever this test inherited (a shell's background job
     * ignores SIGINT) */
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    sigset_t defaults;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGTERM);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGHUP);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF);
    pid_t pid;
    int spawned = posix_spawn(&pid, RAD_TOOL, &actions, &attributes, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    CHECK(spawned == 0);
    if (spawned != 0) {
        close(watch);
        return -1;
    }
    bool sent = false;
    while (!sent) {
        struct pollfd ready = {watch, POLLIN, 0};
        int polled = poll(&ready, 1, 100);
        int status;
        if (polled == 0 && waitpid(pid, &status, WNOHANG) == pid) {
            close(watch);
            test_fail(__FILE__, __LINE__, "the tool ended (status %d) before writing: %s",
                      status, test_read_text(test_path("stderr.txt")));
            return -1;
        }
        if (polled <= 0)
            continue;
        _Alignas(struct inotify_event) char events[4096];
        ssize_t length = read(watch, events, sizeof(events));
        for (ssize_t at = 0; at < length;) {
            const struct inotify_event *event = (const struct inotify_event *)(events + at);
            if (event->len && strncmp(event->name, temp_prefix, strlen(temp_prefix)) == 0 &&
                !sent) {
                CHECK(kill(pid, signal_number) == 0);
                sent = true;
            }
            at += (ssize_t)(sizeof(*event) + event->len);
        }
    }
    close(watch);
    int status = 0;
    CHECK(waitpid(pid, &status, 0) == pid);
    CHECK(WIFSIGNALED(status) && WTERMSIG(status) == signal_number);
    CHECK(test_count_files(temp_prefix) == 0);
    const char *now = test_read_text(test_path(output));
    if (strcmp(now, OLD_CONTENT) != 0) {
        CHECK(strncmp(now, "\x89PNG", 4) == 0); /* replaced whole, then the signal */
        return 0;
    }
    return 1;
}

int main(void)
{
    test_tmpdir();
    static const int signals[] = {SIGTERM, SIGINT, SIGHUP};
    static const char *const names[] = {"SIGTERM", "SIGINT", "SIGHUP"};
    for (int s = 0; s < 3; s++) {
        char output[64];
        snprintf(output, sizeof(output), "out-%s.png", names[s]);
        int hit = 0, attempts = 0;
        for (; attempts < 5 && hit == 0; attempts++)
            hit = render_and_signal(signals[s], output);
        CHECK(hit == 1);
        printf("%s during the write: %s after %d run(s)\n", names[s],
               hit == 1 ? "hit" : "not hit", attempts);
    }
    return test_finish("test_signals");
}
