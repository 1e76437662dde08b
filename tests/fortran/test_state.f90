!> The compensated state: a clock advanced by 10^6 steps of 1e-5 s keeps its digits, and a
!> state assigned to another is copied whole, into the arrays it has when their size fits;
!> product_error is the exact rounding error of a product (a gear ratio's gap); take_state
!> swaps two states (values up to 8 bodies, allocations beyond).
program test_state
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_associated
  use impact1d_kinds, only: wp
  use impact1d_state, only: state_type, new_state, add_compensated, product_error, take_state
  use testing, only: check, finish
  implicit none
  integer, parameter :: n_steps = 1000000
  real(wp), parameter :: dt = 1.0e-5_wp
  ! A plain sum of 10^6 increments of 1e-5 drifts by ~1e-10: far outside this bound.
  real(wp), parameter :: naive_drift_floor = 1.0e-12_wp
  real(wp) :: t, t_lo, naive
  integer :: j

  t = 0.0_wp
  t_lo = 0.0_wp
  naive = 0.0_wp
  do j = 1, n_steps
    call add_compensated(t, t_lo, dt)
    naive = naive + dt
  end do
  ! The exact sum of 10^6 fl(1e-5) is within 1e-15 of 10: hi is it correctly rounded.
  call check(abs(t - 10.0_wp) <= spacing(10.0_wp), 'compensated clock: 10^6 steps of 1e-5 s give 10 s')
  call check(abs(naive - 10.0_wp) > naive_drift_floor, 'the plain sum does drift (the check can fail)')

  call assignment_copies()
  call takes(1)
  call takes(2)
  call takes(8)
  call takes(9)
  call takes(50)
  call product_errors()
  call finish('test_state')

contains

  !> a b - fl(a b) from product_error against the product in quadruple precision (113 bits
  !> hold the 106 of the exact product): random factors over 60 binades of either sign, and
  !> a gear's 3 x 0.1, whose error is not 0 (the check can fail).
  subroutine product_errors()
    integer, parameter :: qp = selected_real_kind(30)
    real(wp) :: a, b, u(4)
    logical :: exact
    integer :: k
    exact = .true.
    do k = 1, 2000
      call random_number(u)
      a = sign((0.5_wp + u(1)) * 2.0_wp**int(60 * u(2) - 30), u(3) - 0.5_wp)
      b = (0.5_wp + u(4)) * 2.0_wp**int(20 * u(1) - 10)
      exact = exact .and. real(product_error(a, b), qp) == real(a, qp) * real(b, qp) - real(a * b, qp)
    end do
    call check(exact, 'product_error: the exact rounding error of 2000 random products')
    call check(product_error(3.0_wp, 0.1_wp) /= 0.0_wp .and. real(product_error(3.0_wp, 0.1_wp), qp) == &
      3.0_qp * real(0.1_wp, qp) - real(3.0_wp * 0.1_wp, qp), 'product_error: 3 x 0.1, not exact in doubles')
    call check(product_error(-1.0_wp, 0.1_wp) == 0.0_wp, 'product_error: a unit ratio is exact')
  end subroutine product_errors

  !> b = a (state_type's own assignment): every field copied; b's arrays kept when they have
  !> a's size (the same address), made anew when not, freed when a has none.
  subroutine assignment_copies()
    type(state_type), target :: a, b, none
    type(c_ptr) :: where_before
    call new_state(3, a)
    call new_state(3, b)
    a%x = [1.0_wp, 2.0_wp, 3.0_wp]
    a%x_lo = [1.0e-17_wp, 0.0_wp, -2.0e-17_wp]
    a%v = [-1.0_wp, 0.5_wp, 0.25_wp]
    a%v_lo = [0.0_wp, 3.0e-18_wp, 0.0_wp]
    a%t = 0.7_wp
    a%t_lo = 1.0e-17_wp
    a%work = 2.5_wp
    a%friction_loss = 0.125_wp
    a%impact_loss = 0.375_wp
    a%damping_loss = 0.0625_wp
    a%drive_work = -1.5_wp
    where_before = c_loc(b%x(1))
    b = a
    call check(c_associated(c_loc(b%x(1)), where_before), 'state assignment: the same size keeps the arrays')
    call check(all(b%x == a%x) .and. all(b%x_lo == a%x_lo) .and. all(b%v == a%v) .and. all(b%v_lo == a%v_lo), &
      'state assignment: the arrays copied')
    call check(b%t == a%t .and. b%t_lo == a%t_lo .and. b%work == a%work .and. b%friction_loss == a%friction_loss &
      .and. b%impact_loss == a%impact_loss .and. b%damping_loss == a%damping_loss .and. b%drive_work == a%drive_work, &
      'state assignment: the clock and the ledger copied')
    call new_state(5, b)
    b = a
    call check(size(b%x) == 3 .and. size(b%v_lo) == 3 .and. all(b%v == a%v), 'state assignment: another size made anew')
    b = none
    call check(.not. allocated(b%x) .and. .not. allocated(b%v), 'state assignment: a state of no bodies frees them')
  end subroutine assignment_copies

  !> take_state(to, from) on n bodies: to has from's values, clock and ledger, from has to's
  !> old arrays' values (the run's trial state, to be overwritten), both at their size.
  subroutine takes(n)
    integer, intent(in) :: n
    type(state_type) :: to, from
    character(len=8) :: bodies
    integer :: i
    write (bodies, '(i0)') n
    call new_state(n, to)
    call new_state(n, from)
    do i = 1, n
      to%x(i) = i
      to%x_lo(i) = 1.0e-17_wp * i
      to%v(i) = -i
      to%v_lo(i) = -1.0e-17_wp * i
      from%x(i) = 100 + i
      from%x_lo(i) = 3.0e-15_wp * i
      from%v(i) = 0.5_wp * i
      from%v_lo(i) = -3.0e-18_wp * i
    end do
    from%t = 0.25_wp
    from%t_lo = 1.0e-18_wp
    from%work = 2.0_wp
    from%damping_loss = 0.5_wp
    call take_state(to, from)
    call check(size(to%x) == n .and. size(to%v_lo) == n .and. size(from%x) == n .and. size(from%v_lo) == n, &
      'take_state, ' // trim(bodies) // ' bodies: both keep their size')
    call check(all(to%x == [(100.0_wp + i, i = 1, n)]) .and. all(to%x_lo == [(3.0e-15_wp * i, i = 1, n)]) .and. &
      all(to%v == [(0.5_wp * i, i = 1, n)]) .and. all(to%v_lo == [(-3.0e-18_wp * i, i = 1, n)]), &
      'take_state, ' // trim(bodies) // ' bodies: to has from''s positions and velocities')
    call check(all(from%x == [(real(i, wp), i = 1, n)]) .and. all(from%v_lo == [(-1.0e-17_wp * i, i = 1, n)]), &
      'take_state, ' // trim(bodies) // ' bodies: from has to''s old values')
    call check(to%t == 0.25_wp .and. to%t_lo == 1.0e-18_wp .and. to%work == 2.0_wp .and. to%damping_loss == 0.5_wp, &
      'take_state, ' // trim(bodies) // ' bodies: the clock and the ledger taken')
  end subroutine takes

end program test_state
