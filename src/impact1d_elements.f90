!> Springs and dampers of an N-body scene (docs/method.md, "Springs and dampers"), read from
!> the model's element records (scene_type's element_*): element j pulls its ends a, b (0 the
!> ground, at x = 0) together with tension k ((x_b - x_a) - rest) + c (v_b - v_a). The
!> N-body engine's counterpart of impact1d_springs (the two-body kernels' lanes): here the
!> ends are looked up by index, so a chain's cost is its number of elements, not N^2.
module impact1d_elements
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  implicit none
  private
  public :: add_element_forces, add_element_rates, element_potential, element_damping_power

contains

  !> y at end e of an element or row (0: the ground, where y is 0).
  pure real(wp) function at_end(y, e)
    real(wp), intent(in) :: y(:)
    integer, intent(in) :: e
    at_end = 0.0_wp
    if (e > 0) at_end = y(e)
  end function at_end

  !> Element j's elongation at positions x + dx (dx: low parts and stage displacements,
  !> added after the large terms cancel).
  pure real(wp) function elongation(scene, j, x, dx)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: x(:), dx(:)
    associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
      elongation = ((at_end(x, b) - at_end(x, a)) - scene%element_rest(j)) + (at_end(dx, b) - at_end(dx, a))
    end associate
  end function elongation

  !> f += the elements' forces at positions x + dx and velocities v.
  pure subroutine add_element_forces(scene, x, dx, v, f)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:), v(:)
    real(wp), intent(inout) :: f(:)
    real(wp) :: tension
    integer :: j
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        tension = scene%element_k(j) * elongation(scene, j, x, dx) + &
          scene%element_c(j) * (at_end(v, b) - at_end(v, a))
        if (a > 0) f(a) = f(a) + tension
        f(b) = f(b) - tension
      end associate
    end do
  end subroutine add_element_forces

  !> df += the rate of the spring forces at velocities v (the dampers' part needs the
  !> accelerations: left out, as impact1d_springs does).
  pure subroutine add_element_rates(scene, v, df)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    real(wp), intent(inout) :: df(:)
    real(wp) :: rate
    integer :: j
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        rate = scene%element_k(j) * (at_end(v, b) - at_end(v, a))
        if (a > 0) df(a) = df(a) + rate
        df(b) = df(b) - rate
      end associate
    end do
  end subroutine add_element_rates

  !> Potential energy stored in the springs at positions x + dx.
  pure real(wp) function element_potential(scene, x, dx) result(pe)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:)
    integer :: j
    pe = 0.0_wp
    do j = 1, scene%n_elements
      pe = pe + scene%element_k(j) * elongation(scene, j, x, dx)**2
    end do
    pe = 0.5_wp * pe
  end function element_potential

  !> Power the dampers dissipate at velocities v.
  pure real(wp) function element_damping_power(scene, v) result(power)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    integer :: j
    power = 0.0_wp
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        power = power + scene%element_c(j) * (at_end(v, b) - at_end(v, a))**2
      end associate
    end do
  end function element_damping_power
end module impact1d_elements
