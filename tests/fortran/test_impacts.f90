!> Impact laws: slot impacts keep momentum and leave the relative velocity at -r times its
!> value; wall impacts reverse one body only; the tutorial's two-body formula holds.
program test_impacts
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type, i_left, i_right, i_slot_min, i_slot_max
  use impact1d_impacts, only: impulse, normal_velocity, most_approaching, restitution_of, &
    joint_inelastic, inelastic_projection, both_limits_closed
  use impact1d_contacts, only: rigid_pair
  use testing, only: check, finish, two_body, on_rows, row_values
  use impact1d_modes, only: pair_rows
  implicit none
  ! One impulse is a handful of flops on O(10) numbers: a few ulps of them.
  real(wp), parameter :: tol = 1.0e-13_wp
  type(scene_type) :: scene
  real(wp) :: v(2), v_after(2), r, expected(2)
  integer :: pattern, k
  logical :: any_both
  logical :: closed(pair_rows), pushed(pair_rows)
  real(wp), parameter :: no_tol(pair_rows) = 0.0_wp
  ! The solver's rounding level of a normal velocity of about 8 m/s (64 ulps of it).
  real(wp), parameter :: u_rounding(pair_rows) = 64.0_wp * epsilon(1.0_wp) * 8.0_wp
  real(wp), parameter :: mass(2) = [1.0_wp, 2.0_wp]
  ! Every contact: walls either side, a slot between the bodies (rows left, right, slot_min,
  ! slot_max: i_left .. i_slot_max are their indices).
  character(len=*), parameter :: contacts = 'm2 = 2, x_left = -1, x_right = 5, d_min = 0.5, d_max = 2'

  call two_body(contacts, scene)
  v = [-9.0_wp, 1.0_wp]
  r = 0.7_wp
  call impulse(scene, i_slot_max, r, v, v_after)
  call check(abs(dot_product(mass, v_after) - dot_product(mass, v)) < tol, &
    'slot impact keeps momentum')
  call check(abs(normal_velocity(scene, i_slot_max, v_after) + r * normal_velocity(scene, i_slot_max, v)) < tol, &
    'slot impact: relative velocity after = -r times before')
  expected(1) = ((1.0_wp - r * 2.0_wp) * v(1) + (1.0_wp + r) * 2.0_wp * v(2)) / 3.0_wp
  expected(2) = ((2.0_wp - r * 1.0_wp) * v(2) + (1.0_wp + r) * 1.0_wp * v(1)) / 3.0_wp
  call check(all(abs(v_after - expected) < tol), "slot impact equals the tutorial's formula")

  call impulse(scene, i_left, 0.5_wp, [-2.0_wp, 3.0_wp], v_after)
  call check(v_after(1) == 1.0_wp .and. v_after(2) == 3.0_wp, 'left wall: v1 -> -r v1, v2 untouched')
  call impulse(scene, i_right, 1.0_wp, [-2.0_wp, 3.0_wp], v_after)
  call check(v_after(1) == -2.0_wp .and. v_after(2) == -3.0_wp, 'right wall: v2 -> -v2, v1 untouched')
  call impulse(scene, i_slot_min, 0.0_wp, [8.0_wp, 0.0_wp], v_after)
  call check(all(abs(v_after - 8.0_wp / 3.0_wp) < tol), 'perfectly inelastic: common velocity 8/3')

  closed = on_rows([.true., .false., .true., .false.])
  call check(most_approaching(scene, closed, [-1.0_wp, -3.0_wp], row_values([0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp])) == i_slot_min, &
    'the fastest approaching closed contact goes first')
  call check(most_approaching(scene, closed, [1.0_wp, 3.0_wp], row_values([0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp])) == 0, &
    'separating contacts get no impulse')

  call two_body(contacts // ', r_left = 1, r_right = 1, r_min = 1, r_max = 1', scene)
  closed = on_rows([.false., .false., .true., .true.])
  call check(restitution_of(scene, i_slot_min, closed) == 0.0_wp, 'a rigid link (both slot limits closed) does not rebound')

  ! A body pinned between a wall and a heavier body, every contact perfectly inelastic: the
  ! joint impact stops both at once (sequential impulses only approach it geometrically).
  call two_body(contacts // ', r_left = 0, r_right = 0, r_min = 0, r_max = 0', scene)
  closed = on_rows([.true., .false., .true., .false.])
  call check(joint_inelastic(scene, closed), 'r = 0 everywhere: one joint inelastic impact')
  call inelastic_projection(scene, closed, [0.0_wp, -5.0_wp], no_tol, v_after, pushed)
  call check(all(v_after == 0.0_wp) .and. all(pushed .eqv. closed), &
    'pinned body: both at rest, impulses on the wall and the slot')
  ! The same contacts, body 2 leaving: only the wall acts, body 2 keeps its velocity.
  call inelastic_projection(scene, closed, [-1.0_wp, 3.0_wp], no_tol, v_after, pushed)
  call check(all(v_after == [0.0_wp, 3.0_wp]) .and. all(pushed .eqv. on_rows([.true., .false., .false., .false.])), &
    'a leaving body is not held back')
  ! Body 1 slower toward the wall than body 2 follows it: the nearest admissible velocity
  ! in the kinetic-energy metric is the common one (the slot face), not the vertex.
  closed = on_rows([.false., .false., .true., .false.])
  call inelastic_projection(scene, closed, [8.0_wp, 0.0_wp], u_rounding, v_after, pushed)
  call impulse(scene, i_slot_min, 0.0_wp, [8.0_wp, 0.0_wp], expected)
  call check(all(v_after == expected), &
    'one closed contact: the projection is the r = 0 impulse')
  ! A rigid link (both slot limits closed) driven into the left wall: the pair stops as one.
  closed = on_rows([.true., .false., .true., .true.])
  call inelastic_projection(scene, closed, [-2.0_wp, -2.0_wp], no_tol, v_after, pushed)
  call check(all(v_after == 0.0_wp) .and. pushed(i_left), 'a rigid pair against a wall stops as one body')
  ! Nothing approaches: nothing changes.
  call inelastic_projection(scene, closed, [1.0_wp, 1.0_wp], no_tol, v_after, pushed)
  call check(all(v_after == 1.0_wp) .and. .not. any(pushed), 'separating contacts: no impulse')
  call two_body(contacts // ', r_left = 0.5, r_right = 0, r_min = 0, r_max = 0', scene)
  closed = on_rows([.true., .false., .true., .false.])
  call check(.not. joint_inelastic(scene, closed), 'an elastic closed contact: no joint projection')
  call two_body(contacts // ', r_left = 0, r_right = 0, r_min = 0, r_max = 0', scene)
  call check(.not. joint_inelastic(scene, on_rows([.false., .false., .true., .false.])), 'one closed contact: one impulse')
  call check(.not. joint_inelastic(scene, on_rows([.false., .false., .true., .true.])), 'a rigid link alone: one impulse')

  ! rigid_pair looks at neighbouring rows once: for every closed pattern it is whether any
  ! row has both limits of its record closed (a rigid link: slot_min and slot_max only).
  call two_body(contacts, scene)
  do pattern = 0, 15
    closed = on_rows([btest(pattern, 0), btest(pattern, 1), btest(pattern, 2), btest(pattern, 3)])
    any_both = .false.
    do k = 1, scene%n_rows
      any_both = any_both .or. both_limits_closed(scene, k, closed)
    end do
    call check(rigid_pair(scene, closed) .eqv. any_both, 'rigid_pair: any record with both limits closed')
    call check(rigid_pair(scene, closed) .eqv. (closed(i_slot_min) .and. closed(i_slot_max)), &
      'rigid_pair: only the slot''s two limits make a rigid pair')
  end do

  call finish('test_impacts')

end program test_impacts
