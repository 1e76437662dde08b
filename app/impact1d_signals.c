/* Signals for the impact1d CLI: a run ended by a signal (any whose default action ends the
 * process: SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGPIPE, SIGALRM, ... and the faults
 * SIGSEGV, SIGBUS, SIGFPE, SIGABRT) removes its temporary output files and then dies of the
 * signal as it would have without us, so no `.part` file is left and the previous outputs
 * are untouched. Only async-signal-safe calls (unlink, sigaction, raise) run in the
 * handler; the paths are copied into fixed buffers before the run starts. Our handler
 * replaces gfortran's backtrace handler (SIGQUIT, SIGSEGV, ...): the death is the default
 * one, without a backtrace. */
#include <signal.h>
#include <string.h>
#include <unistd.h>

#define MAX_PATH_BYTES 4096

static char temporary[2][MAX_PATH_BYTES];
static volatile sig_atomic_t n_temporary = 0;
/* Every signal whose default action is to end the process (Term or Core in signal(7)),
 * but SIGKILL, which cannot be caught; the real-time signals are added at run time. */
static const int handled[] = {
    SIGHUP, SIGINT, SIGQUIT, SIGILL, SIGTRAP, SIGABRT, SIGBUS, SIGFPE, SIGUSR1, SIGSEGV,
    SIGUSR2, SIGPIPE, SIGALRM, SIGTERM, SIGXCPU, SIGXFSZ, SIGVTALRM, SIGPROF, SIGSYS,
#ifdef SIGSTKFLT
    SIGSTKFLT,
#endif
#ifdef SIGIO
    SIGIO,
#endif
#ifdef SIGPWR
    SIGPWR,
#endif
#ifdef SIGEMT
    SIGEMT,
#endif
#ifdef SIGLOST
    SIGLOST,
#endif
};

/* The set of signals the guard handles (and holds while the output is put in place). */
static void handled_set(sigset_t *set)
{
    sigemptyset(set);
    for (size_t i = 0; i < sizeof handled / sizeof handled[0]; ++i) sigaddset(set, handled[i]);
#if defined(SIGRTMIN) && defined(SIGRTMAX)
    for (int sig = SIGRTMIN; sig <= SIGRTMAX; ++sig) sigaddset(set, sig);
#endif
}

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
    handled_set(&set);
    sigprocmask(how, &set, NULL);
}

/* Remove these two files if a signal ends the run (paths NUL-terminated). */
void impact1d_guard_temporaries(const char *first, const char *second)
{
    struct sigaction action;
    sigset_t set;
    const char *paths[2] = {first, second};
    n_temporary = 0;
    for (int i = 0; i < 2; ++i) {
        if (strlen(paths[i]) >= MAX_PATH_BYTES) continue;  /* cannot happen for a path open() took */
        strcpy(temporary[n_temporary], paths[i]);
        n_temporary = n_temporary + 1;
    }
    memset(&action, 0, sizeof action);
    action.sa_handler = remove_temporaries_and_die;
    /* One signal at a time: a second one waits until the first has removed the files. */
    handled_set(&set);
    action.sa_mask = set;
    for (int sig = 1; sig < NSIG; ++sig) {
        struct sigaction previous;
        if (!sigismember(&set, sig)) continue;
        /* A signal the caller ignores (nohup, SIGPIPE under some shells) stays ignored. */
        if (sigaction(sig, NULL, &previous) != 0 || previous.sa_handler == SIG_IGN) continue;
        sigaction(sig, &action, NULL);
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
