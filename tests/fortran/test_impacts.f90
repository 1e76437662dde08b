!> Impact laws: slot impacts keep momentum and leave the relative velocity at -r times its
!> value; wall impacts reverse one body only; the tutorial's two-body formula holds.
program test_impacts
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type, i_left, i_right, i_slot_min, i_slot_max
  use impact1d_impacts, only: impulse, normal_velocity, most_approaching, restitution_of
  use testing, only: check, finish
  implicit none
  ! One impulse is a handful of flops on O(10) numbers: a few ulps of them.
  real(wp), parameter :: tol = 1.0e-13_wp
  type(scene_type) :: scene
  real(wp) :: v(2), v_after(2), r, expected(2)
  logical :: closed(4)

  scene%mass = [1.0_wp, 2.0_wp]
  v = [-9.0_wp, 1.0_wp]
  r = 0.7_wp
  v_after = impulse(scene, i_slot_max, r, v)
  call check(abs(dot_product(scene%mass, v_after) - dot_product(scene%mass, v)) < tol, &
    'slot impact keeps momentum')
  call check(abs(normal_velocity(i_slot_max, v_after) + r * normal_velocity(i_slot_max, v)) < tol, &
    'slot impact: relative velocity after = -r times before')
  expected(1) = ((1.0_wp - r * 2.0_wp) * v(1) + (1.0_wp + r) * 2.0_wp * v(2)) / 3.0_wp
  expected(2) = ((2.0_wp - r * 1.0_wp) * v(2) + (1.0_wp + r) * 1.0_wp * v(1)) / 3.0_wp
  call check(all(abs(v_after - expected) < tol), "slot impact equals the tutorial's formula")

  v_after = impulse(scene, i_left, 0.5_wp, [-2.0_wp, 3.0_wp])
  call check(v_after(1) == 1.0_wp .and. v_after(2) == 3.0_wp, 'left wall: v1 -> -r v1, v2 untouched')
  v_after = impulse(scene, i_right, 1.0_wp, [-2.0_wp, 3.0_wp])
  call check(v_after(1) == -2.0_wp .and. v_after(2) == -3.0_wp, 'right wall: v2 -> -v2, v1 untouched')
  v_after = impulse(scene, i_slot_min, 0.0_wp, [8.0_wp, 0.0_wp])
  call check(all(abs(v_after - 8.0_wp / 3.0_wp) < tol), 'perfectly inelastic: common velocity 8/3')

  closed = [.true., .false., .true., .false.]
  call check(most_approaching(closed, [-1.0_wp, -3.0_wp], [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]) == i_slot_min, &
    'the fastest approaching closed contact goes first')
  call check(most_approaching(closed, [1.0_wp, 3.0_wp], [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]) == 0, &
    'separating contacts get no impulse')

  scene%restitution = 1.0_wp
  closed = [.false., .false., .true., .true.]
  call check(restitution_of(scene, i_slot_min, closed) == 0.0_wp, 'a rigid link (both slot limits closed) does not rebound')

  call finish('test_impacts')

end program test_impacts
