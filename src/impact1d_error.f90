!> Errors travel back to the caller as values: the library never stops the program,
!> because inside the f2py extension a `stop` would kill the user's Python session.
module impact1d_error
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: error_type, raise, status_ok, status_input, status_simulation, fmt

  integer, parameter :: status_ok = 0          !< no error
  integer, parameter :: status_input = 1       !< the scene or its files are wrong: Python's InputError
  integer, parameter :: status_simulation = 2  !< the run cannot go on: Python's SimulationError

  !> An error: its class (status_input or status_simulation) and a one-line message.
  type :: error_type
    integer :: status = status_input
    character(len=:), allocatable :: message
  end type error_type

  !> Shortest text of a number for messages (g0 keeps every digit the user wrote).
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
    error%message = printable(message)
  end subroutine raise

  !> Control bytes (from a file quoted in a message) as \xNN: a message is one line that
  !> cannot move the terminal's cursor or ring its bell. UTF-8 text passes unchanged.
  pure function printable(text) result(shown)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: shown
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
  end function printable

  !> Shortest decimal that reads back as x (1 to 17 digits), in plain notation for
  !> moderate magnitudes: 0.001, 2.5, 1e-12, 6.02e+23.
  pure function fmt_real(x) result(text)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: text
    character(len=40) :: buffer
    character(len=12) :: form
    real(wp) :: back
    integer :: digits, ios, e
    if (x /= x .or. abs(x) > huge(x)) then
      write(buffer, '(g0)') x
      text = trim(adjustl(buffer))
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
      text = trim(adjustl(buffer))
      e = index(text, 'E')
      ! 1.0E-012 -> 1e-12
      text = strip_mantissa(text(:e - 1)) // 'e' // exponent_text(text(e + 1:))
    end if
  end function fmt_real

  pure function strip_mantissa(m) result(out)
    character(len=*), intent(in) :: m
    character(len=:), allocatable :: out
    out = m
    if (index(out, '.') == 0) return
    do while (out(len(out):len(out)) == '0')
      out = out(:len(out) - 1)
    end do
    if (out(len(out):len(out)) == '.') out = out(:len(out) - 1)
  end function strip_mantissa

  pure function exponent_text(e) result(out)
    character(len=*), intent(in) :: e
    character(len=:), allocatable :: out
    integer :: value, ios
    character(len=8) :: buffer
    read(e, *, iostat=ios) value
    write(buffer, '(i0)') value
    out = trim(buffer)
  end function exponent_text

  pure function fmt_int64(i) result(text)
    integer(int64), intent(in) :: i
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write(buffer, '(i0)') i
    text = trim(buffer)
  end function fmt_int64

  pure function fmt_int(i) result(text)
    integer, intent(in) :: i
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write(buffer, '(i0)') i
    text = trim(buffer)
  end function fmt_int
end module impact1d_error
