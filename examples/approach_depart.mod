MODULE ApproachDepart
    ! Approach and depart on the IRB 120 (joulepath example): straight MoveL approaches
    ! and departs blended into MoveJ transfers (MoveL z10 -> MoveJ z50 -> MoveL fine),
    ! between a press on the right and a rack on the left.
    PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.6, [0, 0, 45], [1, 0, 0, 0], 0, 0, 0]];
    CONST robtarget pPress := [[175, -375, 140], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pRack := [[380, 175, 165], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pVia := [[350, -130, 450], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num nClear := 120;

    PROC main()
        WHILE TRUE DO
            MoveL Offs(pPress, 0, 0, nClear), v500, z10, tGripper;
            MoveJ pVia, v1000, z50, tGripper;
            MoveJ Offs(pRack, 0, 0, nClear), v1000, z10, tGripper;
            MoveL pRack, v200, fine, tGripper;
            WaitTime 0.3;
            MoveL Offs(pRack, 0, 0, nClear), v500, z10, tGripper;
            MoveJ pVia, v1000, z50, tGripper;
            MoveJ Offs(pPress, 0, 0, nClear), v1000, z10, tGripper;
            MoveL pPress, v200, fine, tGripper;
            WaitTime 0.3;
        ENDWHILE
    ENDPROC
ENDMODULE
