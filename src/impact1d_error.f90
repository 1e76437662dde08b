!> Errors travel back to the caller as values: the library never stops the program,
!> because inside the f2py extension a `stop` would kill the user's Python session.
module impact1d_error
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
    module procedure fmt_real, fmt_int
  end interface fmt

contains

  !> Allocate `error` with a status and message.
  subroutine raise(error, status, message)
    type(error_type), allocatable, intent(inout) :: error
    integer, intent(in) :: status
    character(len=*), intent(in) :: message
    if (allocated(error)) deallocate(error)
    allocate(error)
    error%status = status
    error%message = message
  end subroutine raise

  pure function fmt_real(x) result(text)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: text
    character(len=40) :: buffer
    write(buffer, '(g0)') x
    text = trim(adjustl(buffer))
  end function fmt_real

  pure function fmt_int(i) result(text)
    integer, intent(in) :: i
    character(len=:), allocatable :: text
    character(len=24) :: buffer
    write(buffer, '(i0)') i
    text = trim(buffer)
  end function fmt_int
end module impact1d_error
