!> Errors travel back to the caller as values: the library never stops the program,
!> because inside the f2py extension a `stop` would kill the user's Python session.
module impact1d_error
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: error_type, raise, status_ok, status_input, status_simulation, status_interrupted, fmt, fmt_width

  integer, parameter :: status_ok = 0          !< no error
  integer, parameter :: status_input = 1       !< the scene or its files are wrong: Python's InputError
  integer, parameter :: status_simulation = 2  !< the run cannot go on: Python's SimulationError
  integer, parameter :: status_interrupted = 4 !< Ctrl-C (SIGINT) during the run: Python's KeyboardInterrupt

  !> An error: its class (status_input or status_simulation) and a one-line message.
  type :: error_type
    integer :: status = status_input
    character(len=:), allocatable :: message
  end type error_type

  !> Shortest text of a number for messages (g0 keeps every digit the user wrote), blank
  !> padded to fmt_width: callers write trim(fmt(x)). No function here returns a string of
  !> deferred length: gfortran 12 keeps such a result's length in a static variable of the
  !> caller, which threads building messages at once overwrite (measured: 6 messages in
  !> 20000 came out corrupted with two threads).
  integer, parameter :: fmt_width = 32
  interface fmt
    module procedure fmt_real, fmt_int, fmt_int64
  end interface fmt

  !> The bytes a message shows escaped (ASCII controls and DEL).
  character(len=*), parameter :: control_bytes = achar(0) // achar(1) // achar(2) // achar(3) // &
    achar(4) // achar(5) // achar(6) // achar(7) // achar(8) // achar(9) // achar(10) // achar(11) // &
    achar(12) // achar(13) // achar(14) // achar(15) // achar(16) // achar(17) // achar(18) // &
    achar(19) // achar(20) // achar(21) // achar(22) // achar(23) // achar(24) // achar(25) // &
    achar(26) // achar(27) // achar(28) // achar(29) // achar(30) // achar(31) // achar(127)

contains

  !> Allocate `error` with a status and message.
  subroutine raise(error, status, message)
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: status
    character(len=*), intent(in) :: message
    if (allocated(error)) deallocate(error)
    allocate(error)
    error%status = status
    call escape_controls(message, error%message)
  end subroutine raise

  !> Control bytes (from a file quoted in a message) as \xNN: a message is one line that
  !> cannot move the terminal's cursor or ring its bell. UTF-8 text passes unchanged.
  pure subroutine escape_controls(text, shown)
    character(len=*), intent(in) :: text
    character(len=:), allocatable, intent(out) :: shown
    character(len=*), parameter :: hex = '0123456789abcdef'
    integer :: j, code
    shown = text
    if (scan(text, control_bytes) == 0) return
    shown = ''
    do j = 1, len(text)
      code = iachar(text(j:j))
      if (code < 32 .or. code == 127) then
        shown = shown // '\x' // hex(code / 16 + 1:code / 16 + 1) // hex(mod(code, 16) + 1:mod(code, 16) + 1)
      else
        shown = shown // text(j:j)
      end if
    end do
  end subroutine escape_controls

  !> Shortest decimal that reads back as x (1 to 17 digits), in plain notation for
  !> moderate magnitudes: 0.001, 2.5, 1e-12, 6.02e+23.
  pure function fmt_real(x) result(out)
    real(wp), intent(in) :: x
    character(len=fmt_width) :: out
    character(len=:), allocatable :: text
    character(len=40) :: buffer
    character(len=12) :: form
    real(wp) :: back
    integer :: digits, ios, e, exponent_value
    if (x /= x .or. abs(x) > huge(x)) then
      write(out, '(g0)') x
      out = adjustl(out)
      return
    end if
    do digits = 1, 17
      write(form, '(a, i0, a)') '(es40.', digits - 1, 'e3)'
      write(buffer, form) x
      read(buffer, *, iostat=ios) back
      if (ios == 0 .and. back == x) exit
    end do
    e = 0
    if (x /= 0.0_wp) e = floor(log10(abs(x)))
    if (e >= -4 .and. e < 15) then
      write(form, '(a, i0, a)') '(f40.', max(digits - 1 - e, 1), ')'
      write(buffer, form) x
      text = trim(adjustl(buffer))
      ! 2.50 -> 2.5, 3.0 stays 3.0
      do while (len(text) > 2 .and. text(len(text):len(text)) == '0' .and. text(len(text) - 1:len(text) - 1) /= '.')
        text = text(:len(text) - 1)
      end do
      if (text(1:1) == '.') text = '0' // text
      if (text(1:2) == '-.') text = '-0' // text(2:)
    else
      ! 1.0E-012 -> 1e-12: the mantissa without trailing zeros (nor a bare point), the
      ! exponent as a plain integer.
      text = trim(adjustl(buffer))
      e = index(text, 'E')
      read(text(e + 1:), *, iostat=ios) exponent_value
      text = text(:e - 1)
      if (index(text, '.') > 0) then
        do while (text(len(text):len(text)) == '0')
          text = text(:len(text) - 1)
        end do
        if (text(len(text):len(text)) == '.') text = text(:len(text) - 1)
      end if
      write(buffer, '(i0)') exponent_value
      text = text // 'e' // trim(buffer)
    end if
    out = text
  end function fmt_real

  !> As write(out, '(i0)') i, digit by digit: the checks of every prepared scene label its
  !> contacts ('x2 - x1') before they know whether a message needs them, and an internal
  !> write cost 4,500 instructions of a 70,000-instruction prepare_scene.
  pure function fmt_int64(i) result(out)
    integer(int64), intent(in) :: i
    character(len=fmt_width) :: out
    character(len=fmt_width) :: digits
    integer(int64) :: rest
    integer :: at
    digits = ''
    at = fmt_width
    rest = i
    do                                   ! (abs of each digit: no overflow at -huge - 1)
      digits(at:at) = achar(iachar('0') + int(abs(mod(rest, 10_int64))))
      rest = rest / 10_int64
      if (rest == 0) exit
      at = at - 1
    end do
    if (i < 0) then
      at = at - 1
      digits(at:at) = '-'
    end if
    out = digits(at:)
  end function fmt_int64

  pure function fmt_int(i) result(out)
    integer, intent(in) :: i
    character(len=fmt_width) :: out
    out = fmt_int64(int(i, int64))
  end function fmt_int
end module impact1d_error
