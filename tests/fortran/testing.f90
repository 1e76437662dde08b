!> The few lines every Fortran unit test needs: count failed checks, say which, and end
!> the test program with a non-zero status if any failed (meson test reads it); and a scene
!> built as a user's is (two_body), so that the tests name what a scene has in the
!> tutorial's words and survive changes of the model's layout.
module testing
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type
  use impact1d_forcing, only: table_type
  use impact1d_scene, only: scene_input, scene_type, build_scene, real_names, n_real, i_f1_table, set_text, n_text, &
    i_m2, i_x2
  use impact1d_chain, only: input_records, mechanism_records
  implicit none
  private
  public :: check, finish, two_body, row_of, seed_random

  integer, save :: failures = 0
  !> What two_body starts from: two unit masses a metre apart, a second's run at 1 ms steps.
  character(len=*), parameter :: base_scene = 'm1 = 1, m2 = 1, x1 = 0, x2 = 1, t_end = 1, dt = 1e-3'

contains

  !> Seed the random numbers with seed(i) = multiplier i + offset, so that a test's random
  !> problems are the same on every run (and a failure can be reproduced).
  subroutine seed_random(multiplier, offset)
    integer, intent(in) :: multiplier, offset
    integer :: seed_size, i
    integer, allocatable :: seed(:)
    call random_seed(size=seed_size)
    allocate(seed(seed_size))
    seed = [(multiplier * i + offset, i = 1, seed_size)]
    call random_seed(put=seed)
  end subroutine seed_random

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

  !> A scene checked and built by build_scene from 'name = value' assignments in the
  !> namelist's names ('m2 = 2, mu1 = 1, g = 10, x_left = -1'), over base_scene; with
  !> f1_table, body 1's force table; with one_body, without m2 and x2 (one body). A scene
  !> the validator refuses ends the test.
  subroutine two_body(assignments, scene, f1_table, one_body)
    character(len=*), intent(in) :: assignments
    type(scene_type), intent(out) :: scene
    type(table_type), intent(in), optional :: f1_table
    logical, intent(in), optional :: one_body
    type(scene_input) :: input
    type(table_type) :: tables(2)
    type(mechanism_records) :: records
    type(error_type), allocatable :: error
    integer :: k
    do k = 1, n_text
      call set_text(input, k, '')
    end do
    call assign(base_scene, input)
    call assign(assignments, input)
    if (present(one_body)) then
      if (one_body) input%given([i_m2, i_x2]) = .false.
    end if
    if (present(f1_table)) then
      call set_text(input, i_f1_table, 'f1_table')
      tables(1) = f1_table
    end if
    call input_records(input, records)
    call build_scene(input, tables, records, scene, error)
    if (allocated(error)) then
      print '(a)', 'two_body(''' // assignments // '''): ' // error%message
      error stop 1
    end if
  end subroutine two_body

  !> The index of the scene's row with this name ('left', 'slot_min', ...); 0 if none.
  pure integer function row_of(scene, name)
    type(scene_type), intent(in) :: scene
    character(len=*), intent(in) :: name
    row_of = findloc(scene%row_name, name, dim=1)
  end function row_of

  !> Set the fields named in a comma-separated list of 'name = value'.
  subroutine assign(assignments, input)
    character(len=*), intent(in) :: assignments
    type(scene_input), intent(inout) :: input
    integer :: start, length, equals, k
    start = 1
    do while (start <= len(assignments))
      length = index(assignments(start:), ',') - 1
      if (length < 0) length = len(assignments) - start + 1
      associate (item => assignments(start:start + length - 1))
        equals = index(item, '=')
        do k = 1, n_real
          if (real_names(k) == adjustl(item(:equals - 1))) exit
        end do
        if (equals == 0 .or. k > n_real) then
          print '(a)', 'two_body: not a scene field assignment: ''' // item // ''''
          error stop 1
        end if
        read(item(equals + 1:), *) input%value(k)
        input%given(k) = .true.
      end associate
      start = start + length + 1
    end do
  end subroutine assign
end module testing
