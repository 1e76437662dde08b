/* What the file system says about a path, for impact1d_files.f90: Fortran's inquire cannot
 * tell a regular file from a FIFO or a device (opening one to find out blocks, or reads
 * forever), nor report why a folder could not be made, nor lock a folder. Paths are
 * NUL-terminated; nothing here keeps state between calls. */
#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* The kinds impact1d_file_kind returns (impact1d_files.f90 names them). */
enum { KIND_MISSING = 0, KIND_REGULAR, KIND_FOLDER, KIND_FIFO, KIND_CHARACTER_DEVICE,
       KIND_BLOCK_DEVICE, KIND_SOCKET, KIND_LINK, KIND_OTHER, KIND_UNKNOWN };

/* The kind of path: links followed when follow is non-zero (stat), else the link itself
 * (lstat). KIND_UNKNOWN when the system cannot tell (no permission to search a folder on
 * the way): the open that follows then reports why. */
int impact1d_file_kind(const char *path, int follow)
{
    struct stat info;
    if ((follow ? stat(path, &info) : lstat(path, &info)) != 0)
        return (errno == ENOENT || errno == ENOTDIR) ? KIND_MISSING : KIND_UNKNOWN;
    if (S_ISREG(info.st_mode)) return KIND_REGULAR;
    if (S_ISDIR(info.st_mode)) return KIND_FOLDER;
    if (S_ISFIFO(info.st_mode)) return KIND_FIFO;
    if (S_ISCHR(info.st_mode)) return KIND_CHARACTER_DEVICE;
    if (S_ISBLK(info.st_mode)) return KIND_BLOCK_DEVICE;
    if (S_ISSOCK(info.st_mode)) return KIND_SOCKET;
    if (S_ISLNK(info.st_mode)) return KIND_LINK;
    return KIND_OTHER;
}

/* Make a folder (mode 0777 less the umask). 0 when it was made or is already a folder,
 * else the system's error number (ENOTDIR when the name is taken by something else). */
int impact1d_make_folder(const char *path)
{
    struct stat info;
    int number;
    if (mkdir(path, 0777) == 0) return 0;
    number = errno;
    /* An existing folder is fine, even where making one is not (a read-only mount). */
    if (stat(path, &info) == 0 && S_ISDIR(info.st_mode)) return 0;
    return number == EEXIST ? ENOTDIR : number;
}

/* The system's text for an error number, NUL-terminated, cut to size bytes. */
void impact1d_error_text(int number, char *text, int size)
{
    if (size <= 0) return;
    strncpy(text, strerror(number), (size_t)size - 1);
    text[size - 1] = '\0';
}

/* Write n bytes to a file descriptor, all of them: 0, or the system's error number. The
 * Fortran runtime drops the errors of its own writes to stdout (gfortran 12: a write to
 * /dev/full or a closed stdout reports success). */
int impact1d_write_all(int fd, const char *text, long n)
{
    while (n > 0) {
        ssize_t done = write(fd, text, (size_t)n);
        if (done < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        text += done;
        n -= done;
    }
    return 0;
}

/* Hold an exclusive lock on a folder until impact1d_unlock_folder: runs that put their
 * outputs in the same folder then do it one after the other. Returns the descriptor to
 * release; -1 where the file system has no such locks (the caller goes on without); -2
 * when another process has held it for wait_seconds: a holder keeps it only while it
 * renames two files, so that one is stopped (SIGSTOP, a suspended job) or hung, and
 * waiting on would hang this run too. */
int impact1d_lock_folder(const char *path, double wait_seconds)
{
    struct timespec start, now, pause = {0, 1000000};  /* 1 ms, doubling up to 100 ms */
    int fd = open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return -1;
    clock_gettime(CLOCK_MONOTONIC, &start);
    while (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EINTR) continue;
        if (errno != EWOULDBLOCK) {
            close(fd);
            return -1;
        }
        clock_gettime(CLOCK_MONOTONIC, &now);
        if ((double)(now.tv_sec - start.tv_sec) + 1e-9 * (double)(now.tv_nsec - start.tv_nsec) >= wait_seconds) {
            close(fd);
            return -2;
        }
        nanosleep(&pause, NULL);
        if (pause.tv_nsec < 100000000L) pause.tv_nsec = 2 * pause.tv_nsec;
    }
    return fd;
}

void impact1d_unlock_folder(int fd)
{
    if (fd >= 0) close(fd);  /* closing the only descriptor releases the lock */
}
