!> Event location: the earliest root of a cubic on a step, including two roots inside one
!> step (a fast bounce) and a graze that must not count; the quiet time of a falling body.
program test_events
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_events, only: earliest_crossing, hermite, poly_value, first_negative
  use testing, only: check, finish
  implicit none
  ! Roots of these cubics are known to the last bit; bisection should land within a few ulps.
  real(wp), parameter :: root_tol = 1.0e-14_wp
  real(wp) :: theta, c(3)

  ! g = (theta - 0.2)(theta - 0.6)(theta + 1): positive, dips below zero on (0.2, 0.6), back up.
  theta = earliest_crossing(expand(0.2_wp, 0.6_wp, -1.0_wp), 1.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp])
  call check(abs(theta - 0.2_wp) < root_tol, 'two roots in one step: the first one is found')

  ! The same dip entirely inside a step whose ends are both positive.
  theta = earliest_crossing(expand(0.3_wp, 0.31_wp, -1.0_wp), 1.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp])
  call check(abs(theta - 0.3_wp) < root_tol, 'a dip between positive ends is not missed')

  ! A graze: (theta - 0.5)^2 touches zero but never goes below: no event.
  theta = earliest_crossing([0.25_wp, -1.0_wp, 1.0_wp, 0.0_wp], 1.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp])
  call check(theta > 1.0_wp, 'a graze with zero approach speed is not an event')

  ! A gap at zero that opens (just after an impact): the root at 0 is not an event.
  theta = earliest_crossing([0.0_wp, 1.0_wp, -0.5_wp, 0.0_wp], 1.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp])
  call check(theta > 1.0_wp, 'an opening gap at zero is not an event')
  ! ... but it closes again at theta = 2 in a longer step.
  theta = earliest_crossing([0.0_wp, 1.0_wp, -0.5_wp, 0.0_wp], 3.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp])
  call check(abs(theta - 2.0_wp) < root_tol, 'an opening gap closes again later in the step')

  ! No root at all, far from zero: the cheap rejection.
  theta = earliest_crossing([5.0_wp, -1.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp])
  call check(theta > 1.0_wp, 'no root when the gap stays positive')

  ! The sign of a zero coefficient does not move the root: the stable root formula for the
  ! extrema takes sign(.., 2 p(2)), and a sum of absent terms may give -0 (one ulp apart).
  theta = earliest_crossing([3.0631851310927851e-4_wp, -0.75281648389631761_wp, 0.0_wp, 8.8975327938671018_wp], &
    1.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp])
  call check(theta == earliest_crossing([3.0631851310927851e-4_wp, -0.75281648389631761_wp, -0.0_wp, &
    8.8975327938671018_wp], 1.0_wp, [1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp]), 'p(2) = -0 finds the root of p(2) = +0')

  ! Hermite dense output reproduces a cubic motion exactly: x = 2 t - 3 t^2 + 0.5 t^3 on [0, 0.7].
  c = hermite(motion(0.7_wp), velocity(0.0_wp), velocity(0.7_wp), 0.7_wp)
  call check(all(abs(c - [2.0_wp, -3.0_wp, 0.5_wp]) < 1.0e-13_wp), 'Hermite is exact for a cubic')

  ! A gap of 5 closing at 1 m/s under -2 m/s^2: 5 - t - t^2 = 0 at t = (sqrt(21) - 1) / 2.
  call check(abs(first_negative(5.0_wp, -1.0_wp, -2.0_wp) - (sqrt(21.0_wp) - 1.0_wp) / 2.0_wp) <= 32.0_wp * eps_wp, &
    'quiet time: the closing root of the quadratic')
  call check(first_negative(5.0_wp, 1.0_wp, 2.0_wp) == huge(1.0_wp), 'quiet time: a gap that never closes')

  call finish('test_events')

contains

  !> Coefficients of (theta - r1)(theta - r2)(theta - r3), lowest order first.
  function expand(r1, r2, r3) result(p)
    real(wp), intent(in) :: r1, r2, r3
    real(wp) :: p(0:3)
    p = [-r1 * r2 * r3, r1 * r2 + r1 * r3 + r2 * r3, -(r1 + r2 + r3), 1.0_wp]
  end function expand

  real(wp) function motion(t)
    real(wp), intent(in) :: t
    motion = 2.0_wp * t - 3.0_wp * t**2 + 0.5_wp * t**3
  end function motion

  real(wp) function velocity(t)
    real(wp), intent(in) :: t
    velocity = 2.0_wp - 6.0_wp * t + 1.5_wp * t**2
  end function velocity

end program test_events
