!> Location: a friction bound crossed inside a step by a force ramp; the quiet time of a
!> falling body.
program test_location
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_scene, only: scene_type
  use impact1d_forcing, only: table_type
  use impact1d_modes, only: mode_type, solve_mode
  use impact1d_location, only: hold_crossing, first_negative
  use impact1d_state, only: lane_state_type
  use testing, only: check, finish, two_body, on_rows
  implicit none
  ! Bisection stops within 2 eps of the clock: a few ulps of t = 0.5.
  real(wp), parameter :: tol = 8.0_wp * eps_wp
  type(scene_type) :: scene
  type(mode_type) :: mode
  logical :: found
  real(wp) :: theta, c(3, 2) = 0.0_wp
  type(lane_state_type) :: a
  type(table_type) :: ramp

  ! Body 1 pushed by f = 20 t: its friction bound 10 is reached at t = 0.5.
  ramp%t = [0.0_wp, 1.0_wp]
  ramp%f = [0.0_wp, 20.0_wp]
  call two_body('m2 = 2, mu1 = 1, mu2 = 1, g = 10, dt = 0.2', scene, ramp)
  call solve_mode(scene%pair, [0.0_wp, 0.0_wp], [20.0_wp, 0.0_wp], on_rows([.false., .false., .false., .false.]), &
    [.true., .true.], [0.0_wp, 0.0_wp], mode, found)
  call check(found .and. all(mode%stuck) .and. mode%n_hold > 0, 'both bodies stuck at t = 0')
  a%t = 0.4_wp
  theta = hold_crossing(scene, mode, a, c, 0.2_wp)
  call check(abs(theta - 0.1_wp) <= tol, 'the bound is crossed 0.1 s into the step from 0.4')
  a%t = 0.1_wp
  call check(hold_crossing(scene, mode, a, c, 0.2_wp) == huge(1.0_wp), 'no crossing in [0.1, 0.3]')

  ! A gap of 5 closing at 1 m/s under -2 m/s^2: 5 - t - t^2 = 0 at t = (sqrt(21) - 1) / 2.
  call check(abs(first_negative(5.0_wp, -1.0_wp, -2.0_wp) - (sqrt(21.0_wp) - 1.0_wp) / 2.0_wp) <= tol * 4.0_wp, &
    'quiet time: the closing root of the quadratic')
  call check(first_negative(5.0_wp, 1.0_wp, 2.0_wp) == huge(1.0_wp), 'quiet time: a gap that never closes')
  call finish('test_location')
end program test_location
