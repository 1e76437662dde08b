/* Signals for the impact1d CLI: an interrupted run (SIGINT, SIGTERM, SIGHUP) removes its
 * temporary output files and then dies of the signal as it would have without us, so no
 * `.part` file is left and the previous outputs are untouched. Only async-signal-safe
 * calls (unlink, sigaction, raise) run in the handler; the paths are copied into fixed
 * buffers before the run starts. */
#include <signal.h>
#include <string.h>
#include <unistd.h>

#define MAX_PATH_BYTES 4096

static char temporary[2][MAX_PATH_BYTES];
static volatile sig_atomic_t n_temporary = 0;
static const int handled[] = {SIGINT, SIGTERM, SIGHUP};

static void remove_temporaries_and_die(int sig)
{
    struct sigaction default_action;
    for (int i = 0; i < n_temporary; ++i) unlink(temporary[i]);
    memset(&default_action, 0, sizeof default_action);
    default_action.sa_handler = SIG_DFL;
    sigaction(sig, &default_action, NULL);
    raise(sig);  /* delivered when the handler returns: the default action ends the process */
}

static void signal_mask(int how)
{
    sigset_t set;
    sigemptyset(&set);
    for (size_t i = 0; i < sizeof handled / sizeof handled[0]; ++i) sigaddset(&set, handled[i]);
    sigprocmask(how, &set, NULL);
}

/* Remove these two files if a signal ends the run (paths NUL-terminated). */
void impact1d_guard_temporaries(const char *first, const char *second)
{
    struct sigaction action;
    const char *paths[2] = {first, second};
    n_temporary = 0;
    for (int i = 0; i < 2; ++i) {
        if (strlen(paths[i]) >= MAX_PATH_BYTES) continue;  /* cannot happen for a path open() took */
        strcpy(temporary[n_temporary], paths[i]);
        n_temporary = n_temporary + 1;
    }
    memset(&action, 0, sizeof action);
    action.sa_handler = remove_temporaries_and_die;
    sigemptyset(&action.sa_mask);
    for (size_t i = 0; i < sizeof handled / sizeof handled[0]; ++i) {
        struct sigaction previous;
        /* A signal the caller ignores (nohup) stays ignored. */
        sigaction(handled[i], NULL, &previous);
        if (previous.sa_handler != SIG_IGN) sigaction(handled[i], &action, NULL);
    }
}

/* While the output is put in place: a signal waits, so the pair is never half replaced. */
void impact1d_hold_signals(void) { signal_mask(SIG_BLOCK); }

/* A signal that waited is delivered now (the guard, if any, removes the temporaries). */
void impact1d_allow_signals(void) { signal_mask(SIG_UNBLOCK); }

/* The temporaries are gone (renamed or removed): a signal that waited now just ends us. */
void impact1d_release_signals(void)
{
    n_temporary = 0;
    signal_mask(SIG_UNBLOCK);
}
