!> The mode solve: stick below the friction bound, slide above it, contact forces only
!> pushing, a body pressed into a wall by a force larger than friction held by the wall.
program test_modes
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type, i_left, i_slot_min
  use impact1d_modes, only: mode_type, solve_mode
  use testing, only: check, finish, two_body, on_rows
  implicit none
  ! Accelerations here are ratios of small integers: exact to a few ulps.
  real(wp), parameter :: tol = 1.0e-13_wp
  type(scene_type) :: scene
  type(mode_type) :: mode
  logical :: found
  real(wp) :: a(2), h(4)
  real(wp), parameter :: no_rate(2) = 0.0_wp

  ! Friction bounds 10 and 20 N; walls either side and a slot between the bodies.
  call two_body('m2 = 2, mu1 = 1, mu2 = 1, g = 10, x_left = -1, x_right = 5, d_min = 0.5, d_max = 2', scene)

  ! Test case 1: forces 6 and -10 below the bounds 10 and 20: both stick.
  call solve_mode(scene%pair, [6.0_wp, -10.0_wp], no_rate, on_rows([.false., .false., .false., .false.]), &
    [.true., .true.], [0.0_wp, 0.0_wp], mode, found)
  call mode%acceleration([6.0_wp, -10.0_wp], a)
  call check(found .and. all(mode%stuck) .and. all(a == 0.0_wp), 'forces below the bound: both bodies stick')

  ! Force 15 > 10 on body 1: it slides forward with a = (15 - 10) / 1.
  call solve_mode(scene%pair, [15.0_wp, 0.0_wp], no_rate, on_rows([.false., .false., .false., .false.]), &
    [.true., .true.], [0.0_wp, 0.0_wp], mode, found)
  call mode%acceleration([15.0_wp, 0.0_wp], a)
  call check(found .and. .not. mode%stuck(1) .and. abs(a(1) - 5.0_wp) < tol .and. a(2) == 0.0_wp, &
    'force above the bound: body 1 breaks away with a = 5')

  ! Exactly at the bound and not rising: it stays stuck.
  call solve_mode(scene%pair, [10.0_wp, 0.0_wp], no_rate, on_rows([.false., .false., .false., .false.]), &
    [.true., .true.], [0.0_wp, 0.0_wp], mode, found)
  call check(found .and. mode%stuck(1), 'force exactly at the bound, constant: stays stuck')
  ! Exactly at the bound and rising: it breaks away now.
  call solve_mode(scene%pair, [10.0_wp, 0.0_wp], [1.0_wp, 0.0_wp], on_rows([.false., .false., .false., .false.]), &
    [.true., .true.], [0.0_wp, 0.0_wp], mode, found)
  call check(found .and. .not. mode%stuck(1), 'force at the bound and rising: breaks away')

  ! Body 1 on the left wall pushed into it by -50 (beyond friction): the wall holds it.
  call solve_mode(scene%pair, [-50.0_wp, 0.0_wp], no_rate, on_rows([.true., .false., .false., .false.]), &
    [.true., .true.], [0.0_wp, 0.0_wp], mode, found)
  call mode%acceleration([-50.0_wp, 0.0_wp], a)
  call check(found .and. all(a == 0.0_wp), 'pressed into a wall beyond friction: held, a = 0')
  ! Pulled away from the wall by +50: contact force would be negative, so it leaves.
  call solve_mode(scene%pair, [50.0_wp, 0.0_wp], no_rate, on_rows([.true., .false., .false., .false.]), &
    [.true., .true.], [0.0_wp, 0.0_wp], mode, found)
  call mode%acceleration([50.0_wp, 0.0_wp], a)
  call check(found .and. .not. mode%active(i_left) .and. abs(a(1) - 40.0_wp) < tol, &
    'pulled off a wall: the contact releases, a = 40')

  ! Frictionless bodies locked by a closed slot_min and pushed together: they move as one.
  call two_body('m2 = 2, x_left = -1, x_right = 5, d_min = 0.5, d_max = 2', scene)
  call solve_mode(scene%pair, [6.0_wp, -3.0_wp], no_rate, on_rows([.false., .false., .true., .false.]), &
    [.false., .false.], [0.0_wp, 0.0_wp], mode, found)
  call mode%acceleration([6.0_wp, -3.0_wp], a)
  call check(found .and. mode%active(i_slot_min) .and. all(abs(a - 1.0_wp) < tol), &
    'bodies pushed together through the slot move as one: a = (6 - 3) / 3')
  h = mode%holds([6.0_wp, -3.0_wp])
  call check(abs(h(1) - 5.0_wp) < tol .and. mode%n_hold == 1, &
    'the slot contact force is 5 N (body 1: 6 - 5 = 1 * a)')

  call finish('test_modes')

end program test_modes
