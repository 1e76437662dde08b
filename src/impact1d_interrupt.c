/* Interrupts for runs driven from Python (impact1d_interrupt.f90 binds these).
 *
 * While the Fortran run holds the thread, Python's own SIGINT handler only sets a flag that
 * the interpreter reads between bytecodes: a 240 s run ignored Ctrl-C until it ended. So
 * the flat API installs this handler (once; again if someone replaced it): it counts the
 * interrupt, where every run in progress sees it at its next checkpoint (every 4096 steps),
 * and passes the signal on to the handler it displaced, so Python raises KeyboardInterrupt
 * as soon as the call returns. A run compares the count with the one it started with, so
 * concurrent runs need no reset. A SIGINT that is ignored or left to its default (which
 * ends the process) is left alone. The CLI does not use this: its own guard
 * (app/impact1d_signals.c) removes its temporary files and dies of the signal. */
#include <pthread.h>
#include <signal.h>
#include <string.h>

static volatile sig_atomic_t interrupts = 0;
static struct sigaction displaced;
static pthread_mutex_t installing = PTHREAD_MUTEX_INITIALIZER;

static void count_and_pass_on(int sig, siginfo_t *info, void *context)
{
    interrupts = interrupts + 1;
    if (displaced.sa_flags & SA_SIGINFO) {
        if (displaced.sa_sigaction != NULL) displaced.sa_sigaction(sig, info, context);
    } else if (displaced.sa_handler != SIG_DFL && displaced.sa_handler != SIG_IGN) {
        displaced.sa_handler(sig);
    }
}

/* Interrupts seen so far (a run stops when this moves on from its start). */
int impact1d_interrupt_count(void) { return interrupts; }

/* Count SIGINT from now on, unless it is already counted, ignored or left to its default. */
void impact1d_catch_interrupts(void)
{
    struct sigaction current, action;
    pthread_mutex_lock(&installing);
    sigaction(SIGINT, NULL, &current);
    if (!(current.sa_flags & SA_SIGINFO && current.sa_sigaction == count_and_pass_on) &&
        (current.sa_flags & SA_SIGINFO || (current.sa_handler != SIG_DFL && current.sa_handler != SIG_IGN))) {
        memset(&action, 0, sizeof action);
        action.sa_sigaction = count_and_pass_on;
        action.sa_flags = SA_SIGINFO | (current.sa_flags & SA_RESTART);
        sigemptyset(&action.sa_mask);
        displaced = current;
        sigaction(SIGINT, &action, NULL);
    }
    pthread_mutex_unlock(&installing);
}
