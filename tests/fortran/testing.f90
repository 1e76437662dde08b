!> The few lines every Fortran unit test needs: count failed checks, say which, and end
!> the test program with a non-zero status if any failed (meson test reads it).
module testing
  implicit none
  private
  public :: check, finish

  integer, save :: failures = 0

contains

  subroutine check(condition, what)
    logical, intent(in) :: condition
    character(len=*), intent(in) :: what
    if (condition) return
    failures = failures + 1
    print '(a)', 'FAILED: ' // what
  end subroutine check

  subroutine finish(test_name)
    character(len=*), intent(in) :: test_name
    if (failures > 0) error stop 1
    print '(a)', test_name // ': all passed'
  end subroutine finish
end module testing
