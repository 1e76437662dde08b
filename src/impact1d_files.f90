!> The file rules the readers and the file sink share: only regular files are read (a FIFO
!> or a device would block or never end, a folder is no file); an output is a regular file,
!> written through a symbolic link to one; folders are made with the system's reason when
!> they cannot be. The system calls are in impact1d_files.c.
module impact1d_files
  use, intrinsic :: iso_c_binding, only: c_int, c_long, c_char, c_null_char, c_ptr, c_associated, c_double
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_error, only: error_type, raise, status_input
  implicit none
  private
  public :: check_input_file, output_target, make_folders, make_temporary, lock_folders, &
    unlock_folders, resolve, resolve_output, write_text, lock_timed_out, lock_wait

  !> lock_folders' handle for a lock another process held past lock_wait() seconds.
  integer, parameter :: lock_timed_out = -2
  !> How long a run waits for a folder lock (the environment's IMPACT1D_LOCK_WAIT, seconds).
  real(c_double), parameter :: default_lock_wait = 60.0_c_double

  !> impact1d_file_kind's answers (impact1d_files.c).
  integer, parameter :: kind_missing = 0, kind_regular = 1, kind_folder = 2, kind_link = 7, &
    kind_unknown = 9
  character(len=*), parameter :: kind_names(0:9) = [character(len=24) :: 'missing', 'a regular file', &
    'a folder', 'a FIFO (named pipe)', 'a character device', 'a block device', 'a socket', &
    'a symbolic link', 'not a regular file', 'unknown']

  interface
    integer(c_int) function c_file_kind(path, follow) bind(C, name='impact1d_file_kind')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: follow
    end function c_file_kind
    integer(c_int) function c_make_folder(path) bind(C, name='impact1d_make_folder')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function c_make_folder
    subroutine c_error_text(number, text, size) bind(C, name='impact1d_error_text')
      import :: c_int, c_char
      integer(c_int), value :: number, size
      character(kind=c_char), intent(out) :: text(*)
    end subroutine c_error_text
    integer(c_int) function c_write_all(fd, text, n) bind(C, name='impact1d_write_all')
      import :: c_int, c_char, c_long
      integer(c_int), value :: fd
      character(kind=c_char), intent(in) :: text(*)
      integer(c_long), value :: n
    end function c_write_all
    integer(c_int) function c_lock_folder(path, wait_seconds) bind(C, name='impact1d_lock_folder')
      import :: c_int, c_char, c_double
      character(kind=c_char), intent(in) :: path(*)
      real(c_double), value :: wait_seconds
    end function c_lock_folder
    subroutine c_unlock_folder(fd) bind(C, name='impact1d_unlock_folder')
      import :: c_int
      integer(c_int), value :: fd
    end subroutine c_unlock_folder
    integer(c_int) function c_getpid() bind(C, name='getpid')
      import :: c_int
    end function c_getpid
    type(c_ptr) function c_realpath(path, resolved) bind(C, name='realpath')
      import :: c_ptr, c_char
      character(kind=c_char), intent(in) :: path(*)
      character(kind=c_char), intent(out) :: resolved(*)
    end function c_realpath
  end interface

contains

  !> What path is: kind_missing, kind_regular, kind_folder, ... (links followed when follow).
  integer function file_kind(path, follow)
    character(len=*), intent(in) :: path
    logical, intent(in) :: follow
    file_kind = c_file_kind(path // c_null_char, merge(1_c_int, 0_c_int, follow))
  end function file_kind

  !> 'a folder', 'a FIFO (named pipe)', 'a character device', ... for a message.
  pure function kind_name(kind) result(name)
    integer, intent(in) :: kind
    character(len=len(kind_names)) :: name     ! blank padded: callers trim
    name = kind_names(max(0, min(kind, ubound(kind_names, 1))))
  end function kind_name

  !> Only a regular file (or a link to one) is read: a folder, FIFO, device or socket is
  !> refused before anything opens it, naming the path and what it is. A missing file
  !> passes (but a link to one): the open that follows says why it cannot be read.
  subroutine check_input_file(path, error)
    character(len=*), intent(in) :: path
    type(error_type), allocatable, intent(out) :: error
    integer :: kind
    logical :: link
    kind = file_kind(path, .true.)
    link = file_kind(path, .false.) == kind_link
    if (kind == kind_missing .and. link) then
      call raise(error, status_input, path // ': is a symbolic link to a missing file')
    else if (kind == kind_folder) then
      call raise(error, status_input, path // ': is a folder, not a file')
    else if (kind /= kind_regular .and. kind /= kind_missing .and. kind /= kind_unknown) then
      call raise(error, status_input, path // ': is ' // trim(kind_name(kind)) // &
        ', not a regular file (only regular files are read)')
    end if
  end subroutine check_input_file

  !> The file an output at path replaces: path itself when it is missing or a regular file;
  !> the file a symbolic link leads to when it is one to a regular file (the output is
  !> written through the link, which stays). Anything else is refused: an existing folder,
  !> FIFO, device or socket (-o /dev/stdout would replace the device's link), or a link
  !> leading nowhere.
  subroutine output_target(path, target, error)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: target
    type(error_type), allocatable, intent(out) :: error
    integer :: kind
    logical :: link
    target = path
    kind = file_kind(path, .true.)
    link = file_kind(path, .false.) == kind_link
    if (kind == kind_missing .and. link) then
      call raise(error, status_input, 'cannot write output ' // path // &
        ': it is a symbolic link to a missing file')
    else if (kind == kind_folder) then
      call raise(error, status_input, 'cannot write output ' // path // ': it is a folder (give a file name)')
    else if (kind /= kind_regular .and. kind /= kind_missing .and. kind /= kind_unknown) then
      call raise(error, status_input, 'cannot write output ' // path // ': it is ' // &
        trim(kind_name(kind)) // ', not a regular file')
    else if (kind == kind_regular .and. link) then
      call resolve(path, target)
      if (len(target) == 0) target = path
    end if
  end subroutine output_target

  !> Make the folders leading to path (-o out/run1/x.dat makes out and out/run1). One that
  !> cannot be made is an input error with the system's reason: a file where a folder
  !> should be, a read-only file system, no permission.
  subroutine make_folders(path, error)
    character(len=*), intent(in) :: path
    type(error_type), allocatable, intent(out) :: error
    character(len=:), allocatable :: text
    integer :: slash
    integer(c_int) :: number
    do slash = 2, len(path)
      if (path(slash:slash) /= '/' .or. path(slash - 1:slash - 1) == '/') cycle
      number = c_make_folder(path(:slash - 1) // c_null_char)
      if (number == 0) cycle
      if (all(file_kind(path(:slash - 1), .true.) /= [kind_missing, kind_unknown])) then
        text = path(:slash - 1) // ' is not a folder'
      else
        call system_reason(number, text)
        text = 'cannot make the folder ' // path(:slash - 1) // ': ' // text
      end if
      call raise(error, status_input, 'cannot write output ' // path // ': ' // text)
      return
    end do
  end subroutine make_folders

  !> The absolute path of an existing file with every link resolved, '' if it does not exist.
  subroutine resolve(path, absolute)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: absolute
    character(kind=c_char, len=4097) :: buffer
    absolute = ''
    if (.not. c_associated(c_realpath(path // c_null_char, buffer))) return
    absolute = buffer(:index(buffer, c_null_char) - 1)
  end subroutine resolve

  !> The absolute path of the file an output at path is or will be: resolve's for an
  !> existing file, else its folder resolved and its name; '' when the folder does not exist.
  subroutine resolve_output(path, absolute)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: absolute
    character(len=:), allocatable :: folder
    call resolve(path, absolute)
    if (len(absolute) > 0) return
    call folder_of(path, folder)
    call resolve(folder, absolute)
    if (len(absolute) == 0) return
    absolute = absolute // '/' // path(index(path, '/', back=.true.) + 1:)
  end subroutine resolve_output

  !> The folder a path is in ('.' for a bare name, '/' for a file at the root).
  subroutine folder_of(path, folder)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: folder
    integer :: slash
    slash = index(path, '/', back=.true.)
    if (slash == 0) then
      folder = '.'
    else
      folder = path(:max(slash - 1, 1))
    end if
  end subroutine folder_of

  !> Write text to file descriptor fd (1 stdout, 2 stderr) as it is; reason is '' when every
  !> byte went, else why not (a full disk, a closed stdout): unlike a Fortran write, which
  !> says nothing of either.
  subroutine write_text(fd, text, reason)
    integer, intent(in) :: fd
    character(len=*), intent(in) :: text
    character(len=:), allocatable, intent(out) :: reason
    integer(c_int) :: number
    reason = ''
    number = c_write_all(int(fd, c_int), text, int(len(text), c_long))
    if (number /= 0) call system_reason(number, reason)
  end subroutine write_text

  !> The system's text for an error number (strerror).
  subroutine system_reason(number, text)
    integer(c_int), intent(in) :: number
    character(len=:), allocatable, intent(out) :: text
    character(kind=c_char, len=256) :: buffer
    call c_error_text(number, buffer, int(len(buffer), c_int))
    text = buffer(:index(buffer, c_null_char) - 1)
  end subroutine system_reason

  !> Create and open for writing a temporary file beside final: final.PID-N.part, N a
  !> number from the clock. Created exclusively (status='new' is O_EXCL), under the next N
  !> while the name is taken (a file a dead run left, a run of another machine sharing the
  !> folder), so two runs writing the same output never share a temporary file. ios and
  !> message are the open's when it fails for another reason.
  subroutine make_temporary(final, unit, name, ios, message)
    character(len=*), intent(in) :: final
    integer, intent(out) :: unit, ios
    character(len=:), allocatable, intent(out) :: name
    character(len=*), intent(out) :: message
    integer(int64) :: count
    integer :: attempt
    character(len=40) :: suffix
    logical :: taken
    call system_clock(count)
    do attempt = 1, 1000
      write(suffix, '(a, i0, a, z6.6, a)') '.', c_getpid(), '-', modulo(count + attempt, 16_int64**6), '.part'
      name = final // trim(suffix)
      open(newunit=unit, file=name, status='new', action='write', iostat=ios, iomsg=message)
      if (ios == 0) return
      inquire(file=name, exist=taken)
      if (.not. taken) return
    end do
  end subroutine make_temporary

  !> Lock the folders of two files (one lock when they share it): runs that put outputs in
  !> the same folder then do it one after the other. Taken in the order of the folders'
  !> absolute names, so two runs never wait for each other's second lock. A handle is -1
  !> where there is no lock to be had, lock_timed_out where another process held it for
  !> lock_wait() seconds (then no lock is held: both handles are released or -1 and -2).
  subroutine lock_folders(first, second, handles)
    character(len=*), intent(in) :: first, second
    integer, intent(out) :: handles(2)
    character(len=:), allocatable :: folder, a, b
    real(c_double) :: wait
    call folder_of(first, folder)
    call resolve(folder, a)
    call folder_of(second, folder)
    call resolve(folder, b)
    handles = -1
    if (len(a) == 0 .or. len(b) == 0) return
    wait = lock_wait()
    if (llt(b, a)) then
      handles(2) = c_lock_folder(b // c_null_char, wait)
      if (handles(2) /= lock_timed_out) handles(1) = c_lock_folder(a // c_null_char, wait)
    else
      handles(1) = c_lock_folder(a // c_null_char, wait)
      if (b /= a .and. handles(1) /= lock_timed_out) handles(2) = c_lock_folder(b // c_null_char, wait)
    end if
    if (any(handles == lock_timed_out)) then
      call unlock_folders(handles)
      handles = merge(lock_timed_out, -1, handles == lock_timed_out)
    end if
  end subroutine lock_folders

  !> Seconds to wait for a folder lock: IMPACT1D_LOCK_WAIT when it is a number of 0 or
  !> more, else 60 (a holder keeps the lock only while it renames two files).
  function lock_wait() result(seconds)
    real(c_double) :: seconds
    character(len=64) :: text
    integer :: length, status, ios
    seconds = default_lock_wait
    call get_environment_variable('IMPACT1D_LOCK_WAIT', text, length, status)
    if (status /= 0 .or. length == 0) return
    read(text, *, iostat=ios) seconds
    if (ios /= 0 .or. .not. (seconds >= 0.0_c_double)) seconds = default_lock_wait
  end function lock_wait

  subroutine unlock_folders(handles)
    integer, intent(in) :: handles(2)
    call c_unlock_folder(int(handles(1), c_int))
    call c_unlock_folder(int(handles(2), c_int))
  end subroutine unlock_folders
end module impact1d_files
