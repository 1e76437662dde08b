!> The bounce series' time in closed form (impact1d_nbody_event), against the sum of its arcs.
program test_event_point
  use impact1d_kinds, only: wp
  use impact1d_nbody_event, only: bounce_series_time
  use testing, only: check, finish
  implicit none
  ! The closed form and a summed geometric series differ by rounding: some ulps.
  real(wp), parameter :: tol = 1.0e-13_wp
  real(wp), parameter :: g = 9.81_wp, u = 0.3_wp, r = 0.6_wp
  real(wp) :: total, speed
  integer :: j

  ! A ball bouncing on the floor under gravity: arc j lasts 2 u r^j / g.
  total = 0.0_wp
  speed = u
  do j = 1, 200
    total = total + 2.0_wp * speed / g
    speed = r * speed
  end do
  call check(abs(bounce_series_time(u, -g, -g, r) - 2.0_wp * u / (g * (1.0_wp - r))) <= tol, &
    'ball on a floor: 2 u / (g (1 - r))')
  call check(abs(bounce_series_time(u, -g, -g, r) - total) <= tol, 'equals the sum of the arcs')
  ! Rising against 2g, falling with g/2: arcs u/2g + u/g, speeds shrink by r/2.
  call check(abs(bounce_series_time(u, -2.0_wp * g, -0.5_wp * g, r) - &
    (u / (2.0_wp * g) + u / g) / (1.0_wp - 0.5_wp * r)) <= tol, 'unequal rise and fall accelerations')
  call check(bounce_series_time(u, -g, -g, 1.0_wp) == huge(1.0_wp), 'elastic: the series never ends')
  call check(bounce_series_time(u, -g, 1.0_wp, r) == huge(1.0_wp), 'no fall back: no series')
  call finish('test_event_point')
end program test_event_point
